// The hysteresis block of flash image v2.2: written by the exporter for a
// model with a hysteresis model (and only then: a joints-only model's image
// stays a 2.1 image byte for byte), parsed into the view and a
// HysteresisModel<float>, and every bad field refused with its own finding,
// even under a valid CRC. Each parse runs in the stopping, the reporting and
// the scanned mode, which must agree.

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/crc32.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/image_hysteresis.hpp"
#include "export/image_writer.hpp"

#include "../support/synthetic_trained_model.hpp"
#include "image_edits.hpp"

namespace cdcr::model {
namespace {

using namespace test_support;  // the image edits of image_edits.hpp

class FlashImageHysteresis : public ::testing::Test {
 protected:
  static test_support::SyntheticModelOptions options() {
    test_support::SyntheticModelOptions o;
    o.hysteresis_operators = 2;
    return o;
  }
  training::TrainedModel model = test_support::synthetic_trained_model(options());
  Bytes image = exporting::write_image(model);

  ImageLayout layout() const {
    const std::uint32_t d = static_cast<std::uint32_t>(model.input_dims());
    return image_layout(static_cast<std::uint32_t>(model.training_points()), d, 2, kImageVersionMajor, 0, 0,
                        image_hysteresis_floats(8, 2));
  }
  // Byte offset of value i (cable * operators + k) of array 0 widths,
  // 1 weights, 2 homing lags.
  std::size_t at(int array, int i) const { return layout().hysteresis_offset + 4 * (16 * array + i); }
};

TEST_F(FlashImageHysteresis, AGoodBlockParsesIntoTheViewAndAModel) {
  ImageView view{};
  ASSERT_EQ(parse_image(image.data(), image.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.version_minor, kImageVersionMinorHysteresis);
  EXPECT_EQ(image[image_field::hysteresis_cables.offset], 8);
  EXPECT_EQ(image[image_field::hysteresis_operators.offset], 2);
  EXPECT_EQ(view.total_size, layout().total_size);
  ASSERT_EQ(view.hysteresis_cables, 8);
  ASSERT_EQ(view.hysteresis_operators, 2);
  EXPECT_EQ(reinterpret_cast<const std::uint8_t*>(view.hysteresis_widths), image.data() + at(0, 0));

  HysteresisModel<float> from_image;
  ASSERT_TRUE(hysteresis_from_image(view, from_image));
  EXPECT_EQ(check_hysteresis(from_image, 8), HysteresisCheck::ok);
  for (int c = 0; c < 8; ++c) {
    for (int k = 0; k < 2; ++k) {
      EXPECT_EQ(from_image.widths_mm[c][k], static_cast<float>(model.hysteresis.widths_mm[c][k]));
      EXPECT_EQ(from_image.weights[c][k], static_cast<float>(model.hysteresis.weights[c][k]));
      EXPECT_EQ(from_image.homing_lag_mm[c][k], static_cast<float>(model.hysteresis.homing_lag_mm[c][k]));
      EXPECT_EQ(get<float>(image, at(1, 2 * c + k)), static_cast<float>(model.hysteresis.weights[c][k]));
    }
  }
  // The rest of the model is where it was: the metadata follows the block.
  EXPECT_EQ(get<std::uint32_t>(image, image_field::metadata_offset.offset), layout().metadata_offset);
  EXPECT_EQ(view.created_unix_s, model.created_unix_s);

  Findings findings;
  ASSERT_EQ(parse_image(image.data(), image.size(), view, ImageCapacity{}, &findings), ImageStatus::ok);
  EXPECT_TRUE(findings.passed_once_for(ImageCheckId::hysteresis, 48))
      << "the hysteresis check passes once for the block's 48 values";
}

TEST_F(FlashImageHysteresis, AJointsOnlyModelIsWrittenAsBeforeAndAddingTheBlockMovesOnlyTheMetadata) {
  training::TrainedModel joints_only = model;
  joints_only.hysteresis = HysteresisModel<double>{};
  const Bytes old_image = exporting::write_image(joints_only);
  EXPECT_EQ(get<std::uint16_t>(old_image, image_field::version_minor.offset), kImageVersionMinor);
  EXPECT_EQ(old_image[image_field::hysteresis_cables.offset], 0);
  EXPECT_EQ(old_image[image_field::hysteresis_operators.offset], 0);
  const ImageLayout old_layout =
      image_layout(static_cast<std::uint32_t>(model.training_points()),
                   static_cast<std::uint32_t>(model.input_dims()), 2);
  EXPECT_EQ(old_image.size(), old_layout.total_size);
  ImageView view{};
  ASSERT_EQ(parse_image(old_image.data(), old_image.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.hysteresis_cables, 0);
  EXPECT_EQ(view.hysteresis_widths, nullptr);
  HysteresisModel<float> none;
  EXPECT_FALSE(hysteresis_from_image(view, none));
  EXPECT_TRUE(none.empty());

  // The same model with the block, both ways it can be made: the bytes
  // before the metadata are the old image's (but the header's minor
  // version, counts, metadata offset and total size).
  const Bytes added = exporting::with_hysteresis_block(old_image, model.hysteresis);
  EXPECT_EQ(added, image);
  for (std::size_t i = kImageHeaderSize; i < old_layout.metadata_offset; ++i) {
    ASSERT_EQ(image[i], old_image[i]) << "byte " << i;
  }
  for (std::uint32_t i = 0; i < kImageMetadataSize; ++i) {
    ASSERT_EQ(image[layout().metadata_offset + i], old_image[old_layout.metadata_offset + i]) << "metadata byte " << i;
  }
}

TEST_F(FlashImageHysteresis, AV21ImageMustKeepTheCountBytesZero) {
  training::TrainedModel joints_only = model;
  joints_only.hysteresis = HysteresisModel<double>{};
  Bytes old_image = exporting::write_image(joints_only);
  put<std::uint8_t>(old_image, image_field::hysteresis_operators.offset, 2);
  reseal(old_image);
  ImageFinding first;
  EXPECT_EQ(parse_all_ways(old_image, first), ImageStatus::bad_header);
  EXPECT_STREQ(first.field, "reserved");
}

struct BadValue {
  const char* name;
  int array;  // 0 widths, 1 weights, 2 homing lags
  int index;
  float value;
  const char* field;  // the finding that must fail first
};

TEST_F(FlashImageHysteresis, EveryBadValueIsRefusedWithItsFindingUnderAValidCrc) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const float lag3 = get<float>(image, at(2, 3));
  const BadValue cases[] = {
      {"NaN width", 0, 5, nan, "hysteresis_width"},
      {"infinite width", 0, 5, inf, "hysteresis_width"},
      {"negative width", 0, 6, -0.01f, "hysteresis_width"},
      {"width beyond the largest", 0, 7, static_cast<float>(kMaxHysteresisWidthMm) * 1.01f, "hysteresis_width"},
      {"NaN weight", 1, 2, nan, "hysteresis_weight"},
      {"negative weight", 1, 9, -0.001f, "hysteresis_weight"},
      {"weights summing above 1", 1, 4, 0.95f, "hysteresis_weight_sum"},
      {"NaN homing lag", 2, 11, nan, "hysteresis_homing_lag"},
      {"homing lag beyond +width", 2, 3, std::abs(lag3) + 1.0f, "hysteresis_homing_lag"},
      {"homing lag beyond -width", 2, 3, -std::abs(lag3) - 1.0f, "hysteresis_homing_lag"},
  };
  for (const BadValue& bad : cases) {
    SCOPED_TRACE(bad.name);
    Bytes damaged = image;
    put<float>(damaged, at(bad.array, bad.index), bad.value);
    reseal(damaged);
    ImageFinding first;
    EXPECT_EQ(parse_all_ways(damaged, first), ImageStatus::invalid_parameters);
    EXPECT_EQ(first.check, ImageCheckId::hysteresis);
    EXPECT_STREQ(first.field, bad.field);
    const int index = bad.array == 1 && std::string(bad.field) == "hysteresis_weight_sum" ? bad.index / 2 : bad.index;
    EXPECT_EQ(first.index, index);
  }
  // A weight sum of exactly 1, and a width of exactly the largest, pass.
  Bytes edge = image;
  put<float>(edge, at(1, 0), 0.5f);
  put<float>(edge, at(1, 1), 0.5f);
  put<float>(edge, at(0, 0), static_cast<float>(kMaxHysteresisWidthMm));
  reseal(edge);
  ImageFinding first;
  EXPECT_EQ(parse_all_ways(edge, first), ImageStatus::ok) << first.field;
}

TEST_F(FlashImageHysteresis, BadCountsAreRefusedBeforeTheLayout) {
  struct BadCounts {
    std::uint8_t cables, operators;
    ImageStatus status;
    const char* field;
  } cases[] = {
      {4, 2, ImageStatus::bad_header, "hysteresis_cables"},      // not 4 per segment
      {8, 0, ImageStatus::bad_header, "hysteresis_operators"},   // cables without operators
      {0, 2, ImageStatus::bad_header, "hysteresis_cables"},      // operators without cables
      {8, 5, ImageStatus::over_capacity, "hysteresis_operators"},  // beyond kMaxHysteresisOperators
  };
  for (const BadCounts& bad : cases) {
    SCOPED_TRACE(bad.field);
    Bytes damaged = image;
    damaged[image_field::hysteresis_cables.offset] = bad.cables;
    damaged[image_field::hysteresis_operators.offset] = bad.operators;
    reseal(damaged);
    ImageFinding first;
    EXPECT_EQ(parse_all_ways(damaged, first), bad.status);
    EXPECT_STREQ(first.field, bad.field);
  }
  // Counts that are valid but not this image's: the layout no longer matches.
  Bytes other = image;
  other[image_field::hysteresis_operators.offset] = 1;
  reseal(other);
  ImageFinding first;
  EXPECT_EQ(parse_all_ways(other, first), ImageStatus::size_mismatch);
}

TEST_F(FlashImageHysteresis, TheExporterRefusesAModelWithTheWrongCounts) {
  training::TrainedModel bad = model;
  bad.hysteresis.cables = 4;
  EXPECT_THROW(exporting::write_image(bad), std::invalid_argument);
  bad = model;
  bad.hysteresis.widths_mm[3][1] = -0.5;
  EXPECT_THROW(exporting::write_image(bad), std::invalid_argument);
}

// The history encodings (v2.5): where each cable last moved, read from the
// block's last operator, after the bend pairs: D = 2n + 4n.
class FlashImageHistory : public FlashImageHysteresis {
 protected:
  static test_support::SyntheticModelOptions history_options() {
    test_support::SyntheticModelOptions o = options();
    o.history = true;
    return o;
  }
  training::TrainedModel history_model = test_support::synthetic_trained_model(history_options());
  Bytes history_image = exporting::write_image(history_model);
  std::size_t history_at(int array, int i) const {
    const ImageLayout l =
        image_layout(static_cast<std::uint32_t>(history_model.training_points()), 12, 2, kImageVersionMajor, 0, 0,
                     image_hysteresis_floats(8, 2));
    return l.hysteresis_offset + 4 * (16 * array + i);
  }
};

TEST_F(FlashImageHistory, IsA25ImageWithTwelveInputs) {
  ImageView view{};
  ASSERT_EQ(parse_image(history_image.data(), history_image.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.version_minor, kImageVersionMinorHistory);
  EXPECT_EQ(view.encoding, InputEncoding::bend_vector_history);
  EXPECT_EQ(view.input_dims, 12u);
  // Without the history the same kind of model stays a 2.2 image.
  ASSERT_EQ(parse_image(image.data(), image.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.version_minor, kImageVersionMinorHysteresis);
}

TEST_F(FlashImageHistory, WhatTheHistoryNeedsIsCheckedUnderAValidCrc) {
  // An older minor version cannot declare the encoding.
  Bytes older = history_image;
  put<std::uint16_t>(older, image_field::version_minor.offset, kImageVersionMinorCableFit);
  reseal(older);
  ImageFinding first;
  EXPECT_EQ(parse_all_ways(older, first), ImageStatus::unsupported_kind);
  EXPECT_STREQ(first.field, "version_minor");
  // The inputs must be the encoding's.
  Bytes dims = history_image;
  put<std::uint16_t>(dims, image_field::input_dims.offset, 8);
  reseal(dims);
  EXPECT_EQ(parse_all_ways(dims, first), ImageStatus::bad_header);
  EXPECT_STREQ(first.field, "input_dims");
  // Without a hysteresis block there is no state to read.
  Bytes without = history_image;
  without[image_field::hysteresis_cables.offset] = 0;
  without[image_field::hysteresis_operators.offset] = 0;
  reseal(without);
  EXPECT_EQ(parse_all_ways(without, first), ImageStatus::bad_header);
  EXPECT_STREQ(first.field, "history_without_hysteresis");
  // The last operator's width divides its lag: zero is refused there, and
  // only there.
  Bytes zero_width = history_image;
  put<float>(zero_width, history_at(0, 2 * 3 + 1), 0.0f);
  reseal(zero_width);
  EXPECT_EQ(parse_all_ways(zero_width, first), ImageStatus::invalid_parameters);
  EXPECT_STREQ(first.field, "hysteresis_history_width");
  EXPECT_EQ(first.index, 2 * 3 + 1);
  Bytes zero_first = history_image;
  put<float>(zero_first, history_at(0, 2 * 3), 0.0f);
  put<float>(zero_first, history_at(2, 2 * 3), 0.0f);  // its homing lag within the width
  reseal(zero_first);
  EXPECT_EQ(parse_all_ways(zero_first, first), ImageStatus::ok) << first.field;
  // The exporter refuses a history model without the block.
  training::TrainedModel no_block = history_model;
  no_block.hysteresis = HysteresisModel<double>{};
  EXPECT_THROW(exporting::write_image(no_block), std::invalid_argument);
}

}  // namespace
}  // namespace cdcr::model
