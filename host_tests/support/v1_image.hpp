#pragma once
// A flash image in format v1, built byte by byte from model/flash-image-v1.md
// with the offsets written out as the specification gives them. It shares no
// code with the exporter (which writes v2 only) or the parser, so the tests
// that load it show that images already on boards still load.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "reference_crc32.hpp"
#include "trained_model/trained_model.hpp"

namespace cdcr::test_support {

namespace v1_detail {

inline std::uint32_t next_multiple_of_8(std::uint32_t at) { return (at + 7) / 8 * 8; }

}  // namespace v1_detail

// The v1 layout of an image with n training points, d inputs and s segments.
struct V1Layout {
  std::uint32_t geometry = 64, parameters = 0, inputs = 0, alpha = 0, metadata = 0, total = 0;
};

inline V1Layout v1_layout(std::uint32_t n, std::uint32_t d, std::uint32_t s) {
  using v1_detail::next_multiple_of_8;
  V1Layout l;
  l.parameters = next_multiple_of_8(l.geometry + 12 * s);
  l.inputs = next_multiple_of_8(l.parameters + 4 * (3 * d + 24));
  l.alpha = next_multiple_of_8(l.inputs + 4 * n * d);
  l.metadata = next_multiple_of_8(l.alpha + 4 * n * 6);
  l.total = next_multiple_of_8(l.metadata + 88) + 4;
  return l;
}

// The model's values as a v1 exporter wrote them. Re-seals the CRC after any
// edit with reseal_v1_image().
inline std::vector<std::uint8_t> v1_image(const training::TrainedModel& m) {
  const auto n = static_cast<std::uint32_t>(m.inputs.rows());
  const auto d = static_cast<std::uint32_t>(m.inputs.cols());
  const auto s = static_cast<std::uint32_t>(m.geometry.segment_count);
  const V1Layout l = v1_layout(n, d, s);
  std::vector<std::uint8_t> image(l.total, 0);
  const auto put = [&image](std::size_t offset, auto value) {
    std::memcpy(image.data() + offset, &value, sizeof value);
  };
  const auto put_f32 = [&put](std::size_t offset, double value) { put(offset, static_cast<float>(value)); };

  std::memcpy(image.data(), "CDGP", 4);
  put(4, std::uint16_t{1});  // version_major
  put(6, std::uint16_t{0});  // version_minor
  put(8, std::uint32_t{64});
  put(12, l.total);
  put(16, n);
  put(20, static_cast<std::uint16_t>(d));
  put(22, std::uint16_t{6});
  put(24, static_cast<std::uint16_t>(s));
  image[26] = 1;  // float32
  image[27] = 1;  // squared exponential ARD
  image[28] = static_cast<std::uint8_t>(m.encoding);
  // 29..31 reserved, zero
  put(32, l.geometry);
  put(36, l.parameters);
  put(40, l.inputs);
  put(44, l.alpha);
  put(48, l.metadata);
  put(52, std::uint32_t{88});
  // 56..63 reserved, zero

  for (std::uint32_t i = 0; i < s; ++i) {
    const auto& seg = m.geometry.segments[i];
    put_f32(l.geometry + 12 * i, seg.backbone_length_mm);
    put_f32(l.geometry + 12 * i + 4, seg.anchor_radius_mm);
    put_f32(l.geometry + 12 * i + 8, seg.theta_max_rad);
  }
  std::size_t at = l.parameters;
  const auto put_all = [&](const auto& values) {
    for (Eigen::Index i = 0; i < values.size(); ++i, at += 4) put_f32(at, values[i]);
  };
  put_all(m.input_mean);
  put_all(m.input_scale);
  put_all(m.length_scales);
  put_all(m.output_mean);
  put_all(m.output_scale);
  put_all(m.signal_variance);
  put_all(m.noise_variance);
  for (std::uint32_t i = 0; i < n; ++i) {
    for (std::uint32_t k = 0; k < d; ++k) {
      put_f32(l.inputs + 4 * (i * d + k),
              (m.inputs(i, k) - m.input_mean[k]) / (m.input_scale[k] * m.length_scales[k]));
    }
    for (std::uint32_t k = 0; k < 6; ++k) put_f32(l.alpha + 4 * (i * 6 + k), m.alpha(i, k));
  }
  put(l.metadata + 0, m.dataset_hash);
  put(l.metadata + 8, m.created_unix_s);
  put(l.metadata + 16, m.validation_samples);
  // 20: reserved, zero
  put(l.metadata + 24, m.metrics);
  std::memcpy(image.data() + l.metadata + 56, m.trainer.data(), std::min<std::size_t>(m.trainer.size(), 32));
  put(l.total - 4, reference_crc32(image.data(), l.total - 4));
  return image;
}

inline void reseal_v1_image(std::vector<std::uint8_t>& image) {
  std::uint32_t total = 0;
  std::memcpy(&total, image.data() + 12, 4);
  const std::uint32_t crc = reference_crc32(image.data(), total - 4);
  std::memcpy(image.data() + total - 4, &crc, 4);
}

}  // namespace cdcr::test_support
