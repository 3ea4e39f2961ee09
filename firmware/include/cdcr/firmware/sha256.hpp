#pragma once
// SHA-256 (FIPS 180-4), incremental and allocation-free: the digest of a
// model transfer, fed a slice per cycle. Host tools use the same code.

#include <cstddef>
#include <cstdint>

namespace cdcr::firmware {

inline constexpr std::size_t kSha256Bytes = 32;

class Sha256 {
 public:
  Sha256() { reset(); }
  void reset();
  void update(const std::uint8_t* data, std::size_t size);
  // Ends the message; the object must be reset() before further use.
  void finish(std::uint8_t (&digest)[kSha256Bytes]);

 private:
  void compress(const std::uint8_t* block);

  std::uint32_t state_[8];
  std::uint8_t buffer_[64];
  std::uint32_t buffered_ = 0;
  std::uint64_t total_bytes_ = 0;
};

// The digest of one buffer.
void sha256(const std::uint8_t* data, std::size_t size, std::uint8_t (&digest)[kSha256Bytes]);

}  // namespace cdcr::firmware
