#pragma once
// A NOR-like flash the runtime writes model updates into, without waiting on
// it: an erase or a program is started, then polled until it is done, so a
// cycle never blocks on the flash.
//
// Semantics every backend implements:
//   - The flash is sector_count() sectors of sector_bytes() bytes, read
//     through one memory-mapped region (read(): the runtime parses a model
//     image in place from it).
//   - Erase sets every byte of a sector to 0xFF.
//   - Program can only clear bits: the stored byte becomes old & new. So
//     programming erased bytes stores the data, and programming the same data
//     again over a program cut short completes it; anything else needs an
//     erase first. A program never crosses a sector boundary and is at most
//     max_program_bytes() long.
//   - One operation at a time: start_*() returns busy while one runs. The
//     data of a program is copied when it starts.
//   - A power loss during an operation leaves it done, not done or torn: an
//     erase may leave part of the sector erased, a program part of its bytes
//     programmed. Nothing else in the flash changes.

#include <cstddef>
#include <cstdint>

#include "cdcr/hal/interface.hpp"

namespace cdcr::hal {

enum class FlashStatus : std::uint8_t {
  ok = 0,     // started (start_*), or the last operation is done (poll)
  busy,       // an operation is still running
  bad_range,  // outside the flash, across a sector or longer than a program may be
  failed,     // the device reported an error (the operation's result is unknown)
};

constexpr const char* to_string(FlashStatus status) {
  switch (status) {
    case FlashStatus::ok: return "ok";
    case FlashStatus::busy: return "busy";
    case FlashStatus::bad_range: return "outside the flash";
    case FlashStatus::failed: return "flash operation failed";
  }
  return "unknown flash status";
}

class Flash : public Interface {
 public:
  virtual std::uint32_t sector_bytes() const = 0;
  virtual std::uint32_t sector_count() const = 0;
  virtual std::uint32_t max_program_bytes() const = 0;
  // The whole flash, memory-mapped (sector_bytes() * sector_count() bytes,
  // 8-byte aligned). Bytes under a running operation read as undefined.
  virtual const std::uint8_t* read() const = 0;

  virtual FlashStatus start_erase(std::uint32_t sector) = 0;
  virtual FlashStatus start_program(std::uint32_t offset, const std::uint8_t* data, std::uint32_t size) = 0;
  // busy while the last operation runs, then its outcome.
  virtual FlashStatus poll() = 0;

  std::uint32_t size_bytes() const { return sector_bytes() * sector_count(); }

 protected:
  ~Flash() = default;
};

}  // namespace cdcr::hal
