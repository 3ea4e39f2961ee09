#pragma once
// A flash image as C source, for linking the model into a firmware build
// instead of flashing it separately. The generated file compiles as C99 and
// as C++ and defines
//
//   const uint8_t  <symbol>[]       the image, 8-byte aligned, in <section>
//   const uint32_t <symbol>_size    its length in bytes
//
// with C linkage, so the firmware declares them as
//   extern const uint8_t <symbol>[]; extern const uint32_t <symbol>_size;
// (inside extern "C" when the firmware is C++) and hands the array to
// parse_image(). The linker script must place <section>, typically in a flash
// region of its own and wrapped in KEEP() so that --gc-sections cannot drop
// an array nothing references by name; without a rule the linker treats it as
// an orphan section and puts it wherever its heuristics choose.

#include <cstddef>
#include <cstdint>
#include <string>

namespace cdcr::exporting {

struct CSourceOptions {
  std::string symbol = "cdcr_model_image";  // a C identifier
  std::string section = ".cdcr_model";      // an ELF section name
  std::string description;                  // one line for the file's comment, e.g. the source file
};

// Throws std::invalid_argument if the symbol is not a C identifier or the
// section name cannot be written inside a C string literal as is.
std::string format_c_source(const std::uint8_t* bytes, std::size_t size, const CSourceOptions& options);

bool is_c_identifier(const std::string& name);
bool is_section_name(const std::string& name);

}  // namespace cdcr::exporting
