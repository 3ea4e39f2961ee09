#pragma once
// What an image in a slot must pass before it may become active: its
// SHA-256 against the one announced (or in the slot's header), computed a
// slice a cycle together with the parser's whole-image checks
// (model::ImageScan: the CRC-32 and the finite payload), then the parse
// with that scan and its geometry against the running model's. No cycle
// reads the whole image.

#include <cstdint>

#include "cdcr/firmware/capacity.hpp"
#include "cdcr/firmware/protocol.hpp"
#include "cdcr/firmware/sha256.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/geometry.hpp"

namespace cdcr::firmware {

class ImageVerifier {
 public:
  using Geometry = model::RobotGeometry<float, kMaxSegments>;

  // The image in place, hashed and scanned from its first byte.
  void begin(const std::uint8_t* image, std::uint32_t size_bytes);
  // As many 64-byte pieces as `units` allow (kUpdateHashUnitsPer64Bytes
  // each, at most kUpdateHashBytesPerCycle); returns the units spent.
  std::uint32_t step(std::uint32_t units);
  bool hashed() const { return hashed_ >= size_; }
  // Once hashed(): the image's SHA-256 is `expected`.
  bool digest_matches(const std::uint8_t (&expected)[kSha256Bytes]);
  // Once hashed(): the image parses (with the scan) and was made for a
  // robot of `running`'s geometry; none, or why not.
  protocol::UpdateReason check(const Geometry& running) const;
  // The scan, for the image's SlotImage: loading it reads no whole image.
  const model::ImageScan& scan() const { return scan_; }

 private:
  const std::uint8_t* image_ = nullptr;
  std::uint32_t size_ = 0;
  Sha256 hash_;
  std::uint32_t hashed_ = 0;
  model::ImageScan scan_;
};

}  // namespace cdcr::firmware
