// The cables block of flash image v2.7: written by the exporter for a robot
// whose segments are not all the paper's four cables at 90 degrees (and only
// then: a four-cable image stays what it was byte for byte), parsed into the
// view and the geometry's cable layouts, and every bad value refused with
// its own finding, even under a valid CRC, in the stopping, the reporting
// and the scanned mode alike.

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "cdcr/model/compensated_kinematics.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "export/image_writer.hpp"

#include "../support/synthetic_trained_model.hpp"
#include "image_edits.hpp"

namespace cdcr::model {
namespace {

using namespace test_support;  // the image edits of image_edits.hpp

constexpr double kPi = 3.14159265358979323846;

test_support::SyntheticModelOptions three_cables(bool residuals = false, bool history = false) {
  test_support::SyntheticModelOptions o;
  o.cables_per_segment = 3;
  o.cable_residuals = residuals;
  o.history = history;
  o.hysteresis_operators = history ? 2 : 0;
  return o;
}

class FlashImageCables : public ::testing::Test {
 protected:
  training::TrainedModel model = test_support::synthetic_trained_model(three_cables());
  Bytes image = exporting::write_image(model);

  ImageView parsed() const {
    ImageView view{};
    EXPECT_EQ(parse_image(image.data(), image.size(), view), ImageStatus::ok);
    return view;
  }
  // Byte offset of float k of segment i's entry in the block.
  std::size_t at(int segment, int k) const {
    const ImageView view = parsed();
    return static_cast<std::size_t>(reinterpret_cast<const std::uint8_t*>(view.cables) - image.data()) +
           4 * static_cast<std::size_t>(segment * image_cables_field::per_segment + k);
  }
};

TEST_F(FlashImageCables, ThreeCablesAt120DegreesComeBackAsTheTrainersLayout) {
  const ImageView view = parsed();
  EXPECT_EQ(view.version_minor, kImageVersionMinorCables);
  ASSERT_NE(view.cables, nullptr);
  EXPECT_EQ(view.cable_count, 6);
  EXPECT_EQ(image_segment_cables(view, 0), 3);
  EXPECT_EQ(image_segment_cables(view, 1), 3);
  // Just before the metadata.
  const ImageLayout layout = image_layout(ImageDims{5, 4, 2, kImageVersionMajor, 0, 0, 0, 0, image_cables_floats(2)});
  EXPECT_EQ(reinterpret_cast<const std::uint8_t*>(view.cables), image.data() + layout.cables_offset);
  EXPECT_EQ(view.total_size, layout.total_size);

  RobotGeometry<double> geometry;
  ASSERT_EQ(geometry_from_image(view, geometry), Status::ok);
  for (int i = 0; i < 2; ++i) {
    const CableLayout<double>& read = geometry.segments[i].cables;
    const CableLayout<double>& trained = model.geometry.segments[i].cables;
    ASSERT_EQ(read.count, 3);
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(read.anchor_x[j], trained.anchor_x[j], 1e-7);
      EXPECT_NEAR(read.anchor_y[j], trained.anchor_y[j], 1e-7);
      EXPECT_NEAR(read.chord_x_weights[j], trained.chord_x_weights[j], 1e-6);
      EXPECT_NEAR(read.chord_y_weights[j], trained.chord_y_weights[j], 1e-6);
      EXPECT_NEAR(read.mean_weights[j], 1.0 / 3.0, 1e-7);
    }
  }
  // Cable 2 at -120 degrees: its anchor is where eq. (2) puts it.
  EXPECT_NEAR(std::atan2(geometry.segments[0].cables.anchor_y[1], geometry.segments[0].cables.anchor_x[1]),
              -2.0 * kPi / 3.0, 1e-7);
}

TEST_F(FlashImageCables, AFourCableModelIsWrittenWithoutTheBlock) {
  const training::TrainedModel four = test_support::synthetic_trained_model();
  const Bytes four_image = exporting::write_image(four);
  ImageView view{};
  ASSERT_EQ(parse_image(four_image.data(), four_image.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.version_minor, kImageVersionMinor);
  EXPECT_EQ(view.cables, nullptr);
  EXPECT_EQ(view.cable_count, 8);
  EXPECT_EQ(four_image.size(), image_layout(5, 4, 2).total_size);
  RobotGeometry<double> geometry;
  ASSERT_EQ(geometry_from_image(view, geometry), Status::ok);
  EXPECT_TRUE(geometry.paper_cables());
}

TEST_F(FlashImageCables, TheInputsFollowTheCounts) {
  // Three cables: one residual (the common mode) and three history inputs a
  // segment.
  const training::TrainedModel with_all = test_support::synthetic_trained_model(three_cables(true, true));
  ASSERT_EQ(with_all.input_dims(), 2 * 2 + 1 * 2 + 3 * 2);
  const Bytes all_image = exporting::write_image(with_all);
  ImageView view{};
  ASSERT_EQ(parse_image(all_image.data(), all_image.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.hysteresis_cables, 6);
  GpCorrection<float> correction;
  ASSERT_EQ(correction.bind(view), Status::ok);
  EXPECT_EQ(correction.history_dims(), 6);
  EXPECT_TRUE(correction.takes_cable_residuals());
  // The measured residuals (common mode, imbalance a segment) go in as the
  // common modes only: the imbalances change nothing.
  JointVector<float> bend(4);
  bend << 0.1f, -0.2f, 0.3f, 0.05f;
  CableResiduals<float> residuals(4);
  residuals << -0.5f, 0.7f, -0.25f, -0.9f;
  CableResiduals<float> other_imbalance = residuals;
  other_imbalance[1] = -3.0f;
  other_imbalance[3] = 2.0f;
  EXPECT_EQ(correction.predict(bend, residuals), correction.predict(bend, other_imbalance));
  CableResiduals<float> other_common_mode = residuals;
  other_common_mode[2] = 0.5f;
  EXPECT_NE(correction.predict(bend, residuals), correction.predict(bend, other_common_mode));
}

TEST_F(FlashImageCables, EveryBadValueIsRefusedWithItsFindingUnderAValidCrc) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  struct BadValue {
    const char* name;
    int segment, k;
    float value;
    const char* field;
  };
  const float pi = static_cast<float>(kPi);
  const BadValue cases[] = {
      {"two cables", 1, image_cables_field::count, 2.0f, "cable_count"},
      {"five cables", 0, image_cables_field::count, 5.0f, "cable_count"},
      {"a count that is not whole", 0, image_cables_field::count, 3.5f, "cable_count"},
      {"NaN angle", 1, image_cables_field::angles + 2, nan, "cable_angle"},
      {"the unused fourth angle not zero", 0, image_cables_field::angles + 3, 0.5f, "cable_angle_unused"},
      // Cables 1 and 3 opposite, cable 2 beside cable 1: all on one line.
      {"anchors on one line", 0, image_cables_field::angles + 1, pi, "cable_anchor_spread"},
  };
  for (const BadValue& bad : cases) {
    SCOPED_TRACE(bad.name);
    Bytes damaged = image;
    if (std::string(bad.field) == "cable_anchor_spread") put<float>(damaged, at(0, image_cables_field::angles + 2), 0.0f);
    put<float>(damaged, at(bad.segment, bad.k), bad.value);
    reseal(damaged);
    ImageFinding first;
    EXPECT_EQ(parse_all_ways(damaged, first), ImageStatus::invalid_parameters);
    EXPECT_EQ(first.check, ImageCheckId::cables);
    EXPECT_STREQ(first.field, bad.field);
  }
}

TEST_F(FlashImageCables, CountsTheHeaderDisagreesWithAreRefused) {
  // Segment 1 of four cables under the residual inputs of three: the
  // header's inputs disagree.
  const training::TrainedModel with_residuals = test_support::synthetic_trained_model(three_cables(true));
  Bytes residual_image = exporting::write_image(with_residuals);
  ImageView view{};
  ASSERT_EQ(parse_image(residual_image.data(), residual_image.size(), view), ImageStatus::ok);
  const auto block_at = [&](const Bytes& bytes, const ImageView& v) {
    return static_cast<std::size_t>(reinterpret_cast<const std::uint8_t*>(v.cables) - bytes.data());
  };
  const std::size_t cables_at = block_at(residual_image, view);
  put<float>(residual_image, cables_at + 4 * image_cables_field::count, 4.0f);
  put<float>(residual_image, cables_at + 4 * (image_cables_field::angles + 3), 1.0f);
  reseal(residual_image);
  ImageFinding first;
  EXPECT_EQ(parse_all_ways(residual_image, first), ImageStatus::invalid_parameters);
  EXPECT_EQ(first.check, ImageCheckId::cables);
  EXPECT_STREQ(first.field, "input_dims");

  // A hysteresis block of 3 cables x 2 operators where the robot has six
  // cables of one: the same floats, the wrong cables.
  test_support::SyntheticModelOptions one_operator = three_cables();
  one_operator.hysteresis_operators = 1;
  Bytes hysteresis_image = exporting::write_image(test_support::synthetic_trained_model(one_operator));
  ASSERT_EQ(parse_image(hysteresis_image.data(), hysteresis_image.size(), view), ImageStatus::ok);
  ASSERT_EQ(view.hysteresis_cables, 6);
  const std::size_t weights_at =
      static_cast<std::size_t>(reinterpret_cast<const std::uint8_t*>(view.hysteresis_weights) - hysteresis_image.data());
  for (int c = 0; c < 6; ++c) put<float>(hysteresis_image, weights_at + 4 * c, 0.1f);
  hysteresis_image[image_field::hysteresis_cables.offset] = 3;
  hysteresis_image[image_field::hysteresis_operators.offset] = 2;
  reseal(hysteresis_image);
  EXPECT_EQ(parse_all_ways(hysteresis_image, first), ImageStatus::invalid_parameters);
  EXPECT_EQ(first.check, ImageCheckId::cables);
  EXPECT_STREQ(first.field, "hysteresis_cables");
}

TEST_F(FlashImageCables, AnImageBefore27HasNoBlockAndMayNotDeclareOne) {
  // The same bytes declared 2.6: the layout no longer fits the size.
  Bytes older = image;
  put<std::uint16_t>(older, image_field::version_minor.offset, kImageVersionMinorHeldOutThreshold);
  reseal(older);
  ImageFinding first;
  EXPECT_EQ(parse_all_ways(older, first), ImageStatus::size_mismatch);
}

}  // namespace
}  // namespace cdcr::model
