// Fuzzes model::parse_image, the one parser the firmware trusts with flash
// contents. Besides "never reads out of bounds" (ASan) and "no undefined
// behaviour" (UBSan), an accepted image must keep every promise of the view:
// each array lies inside the image, every float is finite, and the GP can be
// bound and evaluated from it. The mode that reports every check to a sink
// must reach the same verdict on every input, its first failed finding must
// be the one that decided it, and it must stay inside the buffer as well.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "cdcr/model/crc32.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "fuzz_checks.hpp"

namespace {

using cdcr::fuzz::require;
using namespace cdcr::model;

bool inside(const void* begin, std::size_t bytes, const std::uint8_t* image, std::size_t image_size) {
  const auto* p = static_cast<const std::uint8_t*>(begin);
  return p >= image && bytes <= image_size && p - image <= static_cast<std::ptrdiff_t>(image_size - bytes);
}

void check_floats(const float* values, std::size_t count, const std::uint8_t* image, std::size_t size) {
  require(inside(values, 4 * count, image, size));
  for (std::size_t i = 0; i < count; ++i) require(std::isfinite(values[i]));
}

void check_accepted(const std::uint8_t* bytes, std::size_t size, const ImageView& view, const ImageCapacity& capacity) {
  require(view.total_size <= size);
  require(view.training_points >= 1 && view.training_points <= capacity.max_training_points);
  require(view.segment_count >= 1 && static_cast<std::uint32_t>(view.segment_count) <= capacity.max_segments);
  require(view.input_dims == 2 * view.segment_count);
  require(is_known(view.encoding));
  require(view.version_major == 1 || view.version_major == 2);
  require(is_known(view.model_kind));
  require(view.fitted_rows >= 1);
  if (view.model_kind == ImageModelKind::exact_gp) require(view.fitted_rows == view.training_points);
  const std::size_t n = view.training_points;
  const std::size_t d = static_cast<std::size_t>(view.input_dims);
  const std::size_t image_size = view.total_size;
  check_floats(view.geometry, 3 * static_cast<std::size_t>(view.segment_count), bytes, image_size);
  // The parameter block: means, scales, length scales, then four 6-vectors.
  const std::uint32_t parameter_floats = image_parameter_floats(static_cast<std::uint32_t>(d), view.version_major);
  check_floats(view.input_mean, parameter_floats, bytes, image_size);
  if (view.version_major == 1) {
    require(view.input_min == nullptr && view.input_max == nullptr);
    require(view.noise_variance + kImageOutputs == view.input_mean + parameter_floats);
  } else {
    require(view.input_min == view.noise_variance + kImageOutputs);
    require(view.input_max + d == view.input_mean + parameter_floats);
    for (std::size_t i = 0; i < d; ++i) require(view.input_min[i] <= view.input_max[i]);
  }
  check_floats(view.inputs, n * d, bytes, image_size);
  check_floats(view.alpha, n * kImageOutputs, bytes, image_size);
  require(inside(view.trainer, 32, bytes, image_size));
  for (std::size_t i = 0; i < d; ++i) require(view.input_scale[i] > 0 && view.length_scale[i] > 0);

  // What the firmware does next with a view.
  GpCorrection<double> correction;
  if (correction.bind(view) == Status::ok) {
    JointVector<double> bend = JointVector<double>::Zero(view.input_dims);
    volatile double sink = correction.predict(bend).sum();
    (void)sink;
  }
}

// Remembers the first failed finding and counts the rest.
class FirstFailure final : public ImageCheckSink {
 public:
  void on_finding(const ImageFinding& finding) override {
    require(finding.field != nullptr);
    require(static_cast<int>(finding.check) < kImageCheckCount);
    if (!finding.passed && first_status_ == ImageStatus::ok) first_status_ = finding.status;
    if (!finding.passed) require(finding.status != ImageStatus::ok);
  }
  ImageStatus first_status() const { return first_status_; }

 private:
  ImageStatus first_status_ = ImageStatus::ok;
};

ImageStatus parse_both_ways(const std::uint8_t* bytes, std::size_t size, ImageView& view,
                            const ImageCapacity& capacity) {
  const ImageStatus status = parse_image(bytes, size, view, capacity);
  FirstFailure findings;
  ImageView reported_view{};
  require(parse_image(bytes, size, reported_view, capacity, &findings) == status);
  require(findings.first_status() == status);
  if (status == ImageStatus::ok) {
    require(reported_view.total_size == view.total_size && reported_view.training_points == view.training_points &&
            reported_view.fitted_rows == view.fitted_rows && reported_view.model_kind == view.model_kind &&
            reported_view.geometry == view.geometry && reported_view.input_mean == view.input_mean &&
            reported_view.input_min == view.input_min && reported_view.inputs == view.inputs &&
            reported_view.alpha == view.alpha && reported_view.trainer == view.trainer);
  }
  return status;
}

void parse_and_check(const std::uint8_t* bytes, std::size_t size) {
  const ImageCapacity firmware{};
  // The host tools validate what they write with no capacity limit at all.
  const ImageCapacity unlimited{std::numeric_limits<std::uint32_t>::max(), std::numeric_limits<std::uint16_t>::max()};
  for (const ImageCapacity& capacity : {firmware, unlimited}) {
    ImageView view{};
    if (parse_both_ways(bytes, size, view, capacity) == ImageStatus::ok) check_accepted(bytes, size, view, capacity);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // An exact-size heap copy: one byte past the end is an ASan report.
  std::vector<std::uint8_t> image(data, data + size);
  parse_and_check(image.data(), image.size());

  // Random bytes almost never carry a matching CRC; sealing a copy lets the
  // mutations reach the checks behind the checksum.
  if (size >= kImageHeaderSize + kImageTrailerSize) {
    std::uint32_t total = 0;
    std::memcpy(&total, image.data() + image_field::total_size.offset, 4);
    if (total >= kImageHeaderSize + kImageTrailerSize && total <= size) {
      const std::uint32_t crc = crc32(image.data(), total - kImageTrailerSize);
      std::memcpy(image.data() + total - kImageTrailerSize, &crc, 4);
      parse_and_check(image.data(), image.size());
    }
  }

  // The same bytes one byte off a 4-byte boundary must never be accepted.
  std::vector<std::uint8_t> shifted(size + 1);
  if (size > 0) std::memcpy(shifted.data() + 1, image.data(), size);
  ImageView view{};
  require(parse_both_ways(shifted.data() + 1, size, view, ImageCapacity{}) != ImageStatus::ok);
  return 0;
}
