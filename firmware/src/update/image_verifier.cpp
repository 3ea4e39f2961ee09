#include "cdcr/firmware/update/image_verifier.hpp"

#include <cmath>
#include <cstring>

#include "cdcr/model/compensated_kinematics.hpp"

namespace cdcr::firmware {

namespace {

bool near(float value, float reference) {
  return std::fabs(value - reference) <= kUpdateGeometryTolerance * std::fabs(reference);
}

}  // namespace

void ImageVerifier::begin(const std::uint8_t* image, std::uint32_t size_bytes) {
  image_ = image;
  size_ = size_bytes;
  hash_.reset();
  hashed_ = 0;
  scan_.begin(image, size_bytes);
}

std::uint32_t ImageVerifier::step(std::uint32_t units) {
  // None left for a 64-byte piece leaves it for the next cycle.
  std::uint32_t slice = units / kUpdateHashUnitsPer64Bytes * 64;
  if (slice > kUpdateHashBytesPerCycle) slice = kUpdateHashBytesPerCycle;
  if (slice == 0) return 0;
  const std::uint32_t take = size_ - hashed_ < slice ? size_ - hashed_ : slice;
  hash_.update(image_ + hashed_, take);
  scan_.step(take);  // the parser's whole-image checks, on the same bytes
  hashed_ += take;
  return (take + 63) / 64 * kUpdateHashUnitsPer64Bytes;
}

bool ImageVerifier::digest_matches(const std::uint8_t (&expected)[kSha256Bytes]) {
  std::uint8_t digest[kSha256Bytes];
  hash_.finish(digest);
  hash_.reset();
  return std::memcmp(digest, expected, kSha256Bytes) == 0;
}

// The image's own checks and the robot it was made for.
protocol::UpdateReason ImageVerifier::check(const Geometry& running) const {
  model::ImageView view;
  model::ImageCapacity capacity;
  capacity.max_training_points = kMaxTrainingPoints;
  capacity.max_segments = kMaxSegments;
  capacity.max_variance_rank = model::kMaxVarianceRank;
  const model::ImageStatus parsed = model::parse_image(image_, size_, view, capacity, scan_);
  if (parsed == model::ImageStatus::unsupported_version) return protocol::UpdateReason::unsupported_version;
  if (parsed != model::ImageStatus::ok) return protocol::UpdateReason::image_invalid;
  Geometry incoming;
  if (model::geometry_from_image(view, incoming) != model::Status::ok) return protocol::UpdateReason::image_invalid;
  if (incoming.segment_count != running.segment_count) return protocol::UpdateReason::wrong_segment_count;
  for (int s = 0; s < running.segment_count; ++s) {
    if (!near(incoming.segments[s].backbone_length_mm, running.segments[s].backbone_length_mm) ||
        !near(incoming.segments[s].anchor_radius_mm, running.segments[s].anchor_radius_mm)) {
      return protocol::UpdateReason::wrong_geometry;
    }
  }
  return protocol::UpdateReason::none;
}

}  // namespace cdcr::firmware
