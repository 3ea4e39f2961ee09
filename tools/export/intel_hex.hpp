#pragma once
// Intel HEX encoding of a flash image, for programmers and bootloaders that
// take a file with addresses rather than a raw binary.
//
// Records used: 00 data, 04 extended linear address (the upper 16 bits of
// the 32-bit address, emitted before the first data record and whenever the
// data crosses a 64 KiB boundary), 01 end of file. No record crosses a 64 KiB
// boundary, because a data record's 16-bit address cannot wrap.

#include <cstddef>
#include <cstdint>
#include <string>

namespace cdcr::exporting {

struct IntelHexOptions {
  std::uint32_t base_address = 0;  // where the first byte lands in the target's address space
  int bytes_per_record = 16;       // 16 or 32: what common programmers accept
};

// Throws std::invalid_argument for an unsupported record size or if the data
// would run past the 32-bit address space.
std::string format_intel_hex(const std::uint8_t* bytes, std::size_t size, const IntelHexOptions& options);

}  // namespace cdcr::exporting
