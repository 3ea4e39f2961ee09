// The compliance block of flash image v2.3: written by the exporter for a
// payload model with a compliance model (and only then: every other image
// stays byte for byte what it was), parsed into the view and a
// PayloadCompliance<float>, and every bad value refused with its own
// finding, even under a valid CRC; a block in an image without the payload
// input is refused. Each parse runs in the stopping, the reporting and the
// scanned mode, which must agree.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/image_compliance.hpp"
#include "export/image_writer.hpp"

#include "../support/synthetic_trained_model.hpp"
#include "image_edits.hpp"

namespace cdcr::model {
namespace {

using namespace test_support;  // the image edits of image_edits.hpp

PayloadCompliance<double> two_segment_compliance() {
  PayloadCompliance<double> c;
  c.segments = 2;
  c.weighted_gravity = Vec3<double>(-2.1e-4, 3.0e-5, -1.2e-5);
  c.ratio[0] = 1.0;
  c.ratio[1] = 0.85;
  c.softening_per_rad = 0.4;
  c.unloaded_mass_kg = 0.18;
  return c;
}

class FlashImageCompliance : public ::testing::Test {
 protected:
  static SyntheticModelOptions options() {
    SyntheticModelOptions o;
    o.payload_input = true;
    return o;
  }
  training::TrainedModel payload_model = synthetic_trained_model(options());
  training::TrainedModel model = with_compliance(payload_model);
  Bytes image = exporting::write_image(model);

  static training::TrainedModel with_compliance(training::TrainedModel m) {
    m.compliance = two_segment_compliance();
    return m;
  }
  ImageLayout layout() const {
    return image_layout(static_cast<std::uint32_t>(model.training_points()),
                        static_cast<std::uint32_t>(model.input_dims()), 2, kImageVersionMajor, 0, 1, 0,
                        image_compliance_floats(2));
  }
  // Byte offset of the block's value i: 0..2 the weighted gravity, 3..4 the
  // ratios, 5 the softening, 6 the unloaded mass.
  std::size_t at(int i) const { return layout().compliance_offset + 4 * static_cast<std::size_t>(i); }
};

TEST_F(FlashImageCompliance, AGoodBlockParsesIntoTheViewAndAModel) {
  ImageView view{};
  ASSERT_EQ(parse_image(image.data(), image.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.version_minor, kImageVersionMinorCompliance);
  EXPECT_EQ(image[image_field::compliance_segments.offset], 2);
  EXPECT_EQ(view.total_size, layout().total_size);
  ASSERT_EQ(view.compliance_segments, 2);
  EXPECT_EQ(reinterpret_cast<const std::uint8_t*>(view.compliance_weighted_gravity), image.data() + at(0));
  EXPECT_EQ(get<float>(image, at(4)), 0.85f);
  EXPECT_EQ(get<float>(image, at(5)), 0.4f);
  EXPECT_EQ(get<float>(image, at(6)), 0.18f);

  PayloadCompliance<float, kMaxSegments> from_image;
  ASSERT_TRUE(compliance_from_image(view, from_image));
  EXPECT_EQ(from_image.segments, 2);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(from_image.weighted_gravity[k], float(model.compliance.weighted_gravity[k]));
  EXPECT_EQ(from_image.ratio[0], 1.0f);
  EXPECT_EQ(from_image.ratio[1], 0.85f);
  EXPECT_EQ(from_image.softening_per_rad, 0.4f);
  EXPECT_EQ(from_image.unloaded_mass_kg, 0.18f);
  EXPECT_EQ(get<std::uint32_t>(image, image_field::metadata_offset.offset), layout().metadata_offset);

  Findings findings;
  ASSERT_EQ(parse_image(image.data(), image.size(), view, ImageCapacity{}, &findings), ImageStatus::ok);
  EXPECT_TRUE(findings.passed_once_for(ImageCheckId::compliance, 7))
      << "the compliance check passes once for the block's 7 values";
}

TEST_F(FlashImageCompliance, AModelWithoutItIsWrittenAsBeforeAndAddingTheBlockMovesOnlyTheMetadata) {
  const Bytes old_image = exporting::write_image(payload_model);
  EXPECT_EQ(get<std::uint16_t>(old_image, image_field::version_minor.offset), kImageVersionMinor);
  EXPECT_EQ(old_image[image_field::compliance_segments.offset], 0);
  const ImageLayout old_layout = image_layout(static_cast<std::uint32_t>(model.training_points()),
                                              static_cast<std::uint32_t>(model.input_dims()), 2, kImageVersionMajor,
                                              0, 1);
  EXPECT_EQ(old_image.size(), old_layout.total_size);
  ImageView view{};
  ASSERT_EQ(parse_image(old_image.data(), old_image.size(), view), ImageStatus::ok);
  PayloadCompliance<float, kMaxSegments> none;
  EXPECT_FALSE(compliance_from_image(view, none));
  EXPECT_TRUE(none.empty() && view.compliance_segments == 0 && view.compliance_ratios == nullptr);

  // Added to the old image, the block gives the same bytes, and everything
  // between the header and the metadata stays where it was.
  EXPECT_EQ(exporting::with_compliance_block(old_image, model.compliance), image);
  EXPECT_TRUE(std::equal(image.begin() + kImageHeaderSize, image.begin() + old_layout.metadata_offset,
                         old_image.begin() + kImageHeaderSize));
}

TEST_F(FlashImageCompliance, EveryBadValueIsRefusedWithItsFindingUnderAValidCrc) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const struct {
    const char* name;
    int index;
    float value;
    const char* field;
  } cases[] = {
      {"NaN gravity", 1, nan, "compliance_weighted_gravity"},
      {"infinite gravity", 2, inf, "compliance_weighted_gravity"},
      {"NaN ratio", 3, nan, "compliance_ratio"},
      {"zero ratio", 4, 0.0f, "compliance_ratio"},
      {"negative ratio", 3, -0.5f, "compliance_ratio"},
      {"infinite softening", 5, inf, "compliance_softening"},
      {"softening turning the compliance negative within a quarter turn", 5, -0.65f, "compliance_softening"},
      {"softening turning the compliance to zero at a quarter turn", 5,
       static_cast<float>(-1.0 / kComplianceLargestBendRad), "compliance_softening"},
      {"NaN unloaded mass", 6, nan, "compliance_unloaded_mass"},
      {"negative unloaded mass", 6, -0.01f, "compliance_unloaded_mass"},
  };
  for (const auto& c : cases) {
    Bytes bad = image;
    put<float>(bad, at(c.index), c.value);
    reseal(bad);
    ImageFinding first;
    EXPECT_EQ(parse_all_ways(bad, first), ImageStatus::invalid_parameters) << c.name;
    EXPECT_EQ(first.check, ImageCheckId::compliance) << c.name;
    EXPECT_STREQ(first.field, c.field) << c.name;
  }
  // The softening's bound is the quarter turn's, not zero: -0.6 keeps
  // 1 + s |b| above 0.05 there.
  Bytes soft = image;
  put<float>(soft, at(5), -0.6f);
  reseal(soft);
  ImageFinding none;
  EXPECT_EQ(parse_all_ways(soft, none), ImageStatus::ok);
}

TEST_F(FlashImageCompliance, ABlockWithoutThePayloadInputForOtherSegmentsOrInAnOlderImageIsRefused) {
  // The count byte set by hand, under a valid CRC: the field that fails
  // first, of a bad_header refusal.
  const auto refused_field = [](Bytes bytes, std::uint8_t count) {
    put<std::uint8_t>(bytes, image_field::compliance_segments.offset, count);
    reseal(bytes);
    ImageFinding first;
    EXPECT_EQ(parse_all_ways(bytes, first), ImageStatus::bad_header);
    return std::string(first.field);
  };
  // It names another robot; or it is set in an image older than v2.3,
  // where the byte is reserved.
  EXPECT_EQ(refused_field(image, 3), "compliance_segments");
  EXPECT_EQ(refused_field(exporting::write_image(payload_model), 2), "reserved");
  ImageFinding first;

  // A joints-only model's image given the block by hand (its layout made
  // right, its CRC valid): the sag needs the payload.
  SyntheticModelOptions joints_only_options;
  training::TrainedModel joints_only = synthetic_trained_model(joints_only_options);
  const Bytes plain = exporting::write_image(joints_only);
  const std::uint32_t n = static_cast<std::uint32_t>(joints_only.training_points());
  const std::uint32_t d = static_cast<std::uint32_t>(joints_only.input_dims());
  const ImageLayout old_layout = image_layout(n, d, 2);
  const ImageLayout new_layout = image_layout(n, d, 2, kImageVersionMajor, 0, 0, 0, image_compliance_floats(2));
  Bytes forged(new_layout.total_size, 0);
  std::copy(plain.begin(), plain.begin() + old_layout.metadata_offset, forged.begin());
  std::copy(plain.begin() + old_layout.metadata_offset, plain.begin() + old_layout.metadata_offset + kImageMetadataSize,
            forged.begin() + new_layout.metadata_offset);
  put<std::uint16_t>(forged, image_field::version_minor.offset, kImageVersionMinorCompliance);
  put<std::uint8_t>(forged, image_field::compliance_segments.offset, 2);
  put<std::uint32_t>(forged, image_field::total_size.offset, new_layout.total_size);
  put<std::uint32_t>(forged, image_field::metadata_offset.offset, new_layout.metadata_offset);
  for (int i = 0; i < 7; ++i) put<float>(forged, new_layout.compliance_offset + 4 * i, 1e-4f);
  reseal(forged);
  EXPECT_EQ(parse_all_ways(forged, first), ImageStatus::bad_header);
  EXPECT_STREQ(first.field, "compliance_without_payload_input");
  // The exporter refuses to write one.
  joints_only.compliance = two_segment_compliance();
  EXPECT_THROW(exporting::write_image(joints_only), std::invalid_argument);
  EXPECT_THROW(exporting::with_compliance_block(plain, two_segment_compliance()), std::invalid_argument);
}

TEST_F(FlashImageCompliance, StatusMessagesAreOneLine) {
  for (const ImageStatus s : {ImageStatus::bad_header, ImageStatus::invalid_parameters}) {
    EXPECT_EQ(std::string(to_string(s)).find('\n'), std::string::npos);
  }
  EXPECT_STREQ(to_string(ImageCheckId::compliance), "compliance");
}

}  // namespace
}  // namespace cdcr::model
