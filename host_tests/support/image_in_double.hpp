#pragma once
// An image's model read back in double, for the reference computations the
// float32 paths are checked against: its geometry, and its GP bound to the
// image's bytes (which must outlive it).

#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/gp_correction.hpp"

namespace cdcr::test_support {

struct ImageInDouble {
  model::RobotGeometry<double> geometry;
  model::GpCorrection<double, double> correction;
};

inline testing::AssertionResult read_image_in_double(const std::vector<std::uint8_t>& image, ImageInDouble& out) {
  model::ImageView view{};
  if (model::parse_image(image.data(), image.size(), view) != model::ImageStatus::ok)
    return testing::AssertionFailure() << "the image does not parse";
  if (model::geometry_from_image(view, out.geometry) != model::Status::ok)
    return testing::AssertionFailure() << "the image's geometry is refused";
  if (out.correction.bind(view) != model::Status::ok) return testing::AssertionFailure() << "the GP does not bind";
  return testing::AssertionSuccess();
}

}  // namespace cdcr::test_support
