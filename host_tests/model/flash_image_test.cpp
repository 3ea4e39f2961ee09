// Flash image format v2 (model/flash-image-v2.md): an image written by the
// exporter parses into a zero-copy view holding the model's values, a v1
// image built by hand from model/flash-image-v1.md still parses, and every
// way an image can be wrong is refused with its own status, in the order the
// specification's validation table gives. Damaged images are made by editing
// a valid one; where a check sits behind the CRC, the CRC is recomputed so the
// edit reaches that check. Every parse also runs in the mode that reports
// every check to a sink, which must reach the same verdict.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/crc32.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "export/image_writer.hpp"
#include "train/trainer.hpp"

#include "../support/synthetic_trained_model.hpp"
#include "../support/v1_image.hpp"
#include "image_edits.hpp"

namespace cdcr::model {
namespace {

using namespace test_support;  // the image edits of image_edits.hpp

// The reporting parse of the same bytes.
ImageStatus parse_reporting(const Bytes& image, Findings& findings, const ImageCapacity& capacity = {}) {
  ImageView view{};
  return parse_image(image.data(), image.size(), view, capacity, &findings);
}

// The verdict with the whole-image checks scanned first, `slice` bytes at a
// time (as the firmware's model update scans beside its hash).
ImageStatus parse_scanned(const Bytes& image, std::uint32_t slice, const ImageCapacity& capacity = {}) {
  ImageScan scan;
  scan.begin(image.data(), image.size());
  for (std::size_t i = 0; i <= image.size() / slice + 1 && !scan.step(slice); ++i) {
  }
  ImageView view{};
  return parse_image(image.data(), image.size(), view, capacity, scan);
}

// The plain verdict, after checking that the reporting mode and the scanned
// parse reach the same one, and that the reporting mode's first failed
// finding is the one that decided it.
ImageStatus parse(const Bytes& image, const ImageCapacity& capacity = {}) {
  ImageView view{};
  const ImageStatus status = parse_image(image.data(), image.size(), view, capacity);
  for (std::uint32_t slice : {4u, 64u, 1024u}) {
    EXPECT_EQ(parse_scanned(image, slice, capacity), status) << "the parse scanned " << slice << " bytes at a time disagrees";
  }
  Findings findings;
  EXPECT_EQ(parse_reporting(image, findings, capacity), status) << "the reporting parse disagrees";
  const ImageFinding* first = findings.first_failure();
  if (status == ImageStatus::ok) {
    EXPECT_EQ(first, nullptr) << "a valid image with a failed finding: " << (first ? first->field : "");
  } else if (first == nullptr) {
    ADD_FAILURE() << "rejected, but no finding failed";
  } else {
    EXPECT_EQ(first->status, status) << "first failed finding: " << to_string(first->check) << " " << first->field;
  }
  return status;
}

// The verdict and, in the reporting mode, that `check` is among the failures.
ImageStatus parse_failing(const Bytes& image, ImageCheckId check, const ImageCapacity& capacity = {}) {
  const ImageStatus status = parse(image, capacity);
  Findings findings;
  parse_reporting(image, findings, capacity);
  EXPECT_TRUE(findings.failed(check)) << "check " << to_string(check) << " did not fail";
  return status;
}

class FlashImage : public ::testing::Test {
 protected:
  training::TrainedModel model = test_support::synthetic_trained_model();
  Bytes image = exporting::write_image(model);
  ImageLayout layout = image_layout(5, 4, 2);

  std::uint32_t geometry_floats() const { return 3 * 2; }
  std::uint32_t parameter_floats() const { return image_parameter_floats(4); }
  std::uint32_t input_floats() const { return 5 * 4; }
  std::uint32_t alpha_floats() const { return 5 * kImageOutputs; }
};

// --- a valid image -----------------------------------------------------------

TEST_F(FlashImage, LayoutIsTheOneTheDimsImply) {
  ASSERT_EQ(image.size(), layout.total_size);
  EXPECT_EQ(std::memcmp(image.data(), "CDGP", 4), 0);
  EXPECT_EQ(get<std::uint32_t>(image, image_field::total_size.offset), layout.total_size);
  EXPECT_EQ(get<std::uint32_t>(image, image_field::geometry_offset.offset), 64u);
  EXPECT_EQ(get<std::uint32_t>(image, image_field::parameters_offset.offset), layout.parameters_offset);
  EXPECT_EQ(get<std::uint32_t>(image, image_field::inputs_offset.offset), layout.inputs_offset);
  EXPECT_EQ(get<std::uint32_t>(image, image_field::alpha_offset.offset), layout.alpha_offset);
  EXPECT_EQ(get<std::uint32_t>(image, image_field::metadata_offset.offset), layout.metadata_offset);
  // Each block at the next multiple of 8 after the previous one, padding zero.
  const std::uint32_t ends[] = {64 + 4 * geometry_floats(), layout.parameters_offset + 4 * parameter_floats(),
                                layout.inputs_offset + 4 * input_floats(), layout.alpha_offset + 4 * alpha_floats(),
                                layout.metadata_offset + kImageMetadataSize};
  const std::uint32_t next[] = {layout.parameters_offset, layout.inputs_offset, layout.alpha_offset,
                                layout.metadata_offset, layout.total_size - kImageTrailerSize};
  for (int b = 0; b < 5; ++b) {
    EXPECT_EQ(next[b] % 8, 0u);
    EXPECT_EQ(next[b], (ends[b] + 7) / 8 * 8) << "block " << b;
    for (std::uint32_t i = ends[b]; i < next[b]; ++i) EXPECT_EQ(image[i], 0) << "padding byte " << i;
  }
}

TEST_F(FlashImage, ParsesIntoAZeroCopyViewOfTheModel) {
  ImageView view{};
  ASSERT_EQ(parse_image(image.data(), image.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.version_major, 2);
  EXPECT_EQ(view.version_minor, kImageVersionMinor);
  EXPECT_EQ(view.model_kind, ImageModelKind::exact_gp);
  EXPECT_EQ(view.fitted_rows, 5u);
  EXPECT_EQ(view.total_size, image.size());
  EXPECT_EQ(view.training_points, 5u);
  EXPECT_EQ(view.input_dims, 4);
  EXPECT_EQ(view.segment_count, 2);
  EXPECT_EQ(view.encoding, InputEncoding::bend_vector);

  // The arrays are the caller's bytes, not copies.
  const auto at = [this](std::uint32_t offset) { return reinterpret_cast<const float*>(image.data() + offset); };
  EXPECT_EQ(view.geometry, at(64));
  EXPECT_EQ(view.input_mean, at(layout.parameters_offset));
  EXPECT_EQ(view.inputs, at(layout.inputs_offset));
  EXPECT_EQ(view.alpha, at(layout.alpha_offset));

  for (int s = 0; s < 2; ++s) {
    EXPECT_EQ(view.geometry[3 * s + 0], static_cast<float>(model.geometry.segments[s].backbone_length_mm));
    EXPECT_EQ(view.geometry[3 * s + 1], static_cast<float>(model.geometry.segments[s].anchor_radius_mm));
    EXPECT_EQ(view.geometry[3 * s + 2], static_cast<float>(model.geometry.segments[s].theta_max_rad));
  }
  // The range of the rows the model was fitted on, after the v1 parameters.
  EXPECT_EQ(view.input_min, view.noise_variance + kImageOutputs);
  EXPECT_EQ(view.input_max, view.input_min + 4);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(view.input_min[k], static_cast<float>(model.inputs.col(k).minCoeff()));
    EXPECT_EQ(view.input_max[k], static_cast<float>(model.inputs.col(k).maxCoeff()));
  }
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(view.input_mean[k], static_cast<float>(model.input_mean[k]));
    EXPECT_EQ(view.input_scale[k], static_cast<float>(model.input_scale[k]));
    EXPECT_EQ(view.length_scale[k], static_cast<float>(model.length_scales[k]));
  }
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(view.output_mean[k], static_cast<float>(model.output_mean[k]));
    EXPECT_EQ(view.output_scale[k], static_cast<float>(model.output_scale[k]));
    EXPECT_EQ(view.signal_variance[k], static_cast<float>(model.signal_variance[k]));
    EXPECT_EQ(view.noise_variance[k], static_cast<float>(model.noise_variance[k]));
  }
  // Inputs in kernel coordinates, computed in double and rounded once.
  for (int i = 0; i < 5; ++i) {
    for (int k = 0; k < 4; ++k) {
      const double z = (model.inputs(i, k) - model.input_mean[k]) / (model.input_scale[k] * model.length_scales[k]);
      EXPECT_EQ(view.inputs[i * 4 + k], static_cast<float>(z)) << i << "," << k;
    }
    for (int k = 0; k < 6; ++k) EXPECT_EQ(view.alpha[i * 6 + k], static_cast<float>(model.alpha(i, k)));
  }

  EXPECT_EQ(view.dataset_hash, model.dataset_hash);
  EXPECT_EQ(view.created_unix_s, model.created_unix_s);
  EXPECT_EQ(view.validation_samples, model.validation_samples);
  EXPECT_EQ(std::memcmp(&view.metrics, &model.metrics, sizeof(ImageMetrics)), 0);
  EXPECT_EQ(std::string(view.trainer, strnlen(view.trainer, 32)), model.trainer);
}

TEST_F(FlashImage, JointAngleEncodingIsCarried) {
  test_support::SyntheticModelOptions options;
  options.encoding = InputEncoding::joint_angles;
  const Bytes joint_image = exporting::write_image(test_support::synthetic_trained_model(options));
  ImageView view{};
  ASSERT_EQ(parse_image(joint_image.data(), joint_image.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.encoding, InputEncoding::joint_angles);
}

TEST_F(FlashImage, TrainerNameMayFillAllThirtyTwoBytes) {
  model.trainer = std::string(40, 'x');
  const Bytes long_name = exporting::write_image(model);
  ImageView view{};
  ASSERT_EQ(parse_image(long_name.data(), long_name.size(), view), ImageStatus::ok);
  EXPECT_EQ(std::string(view.trainer, strnlen(view.trainer, 32)), std::string(32, 'x'));
}

TEST_F(FlashImage, ChecksumIsZlibsCrc32) {
  // The standard check value of CRC-32/ISO-HDLC, which zlib computes.
  const std::string check = "123456789";
  const auto* check_bytes = reinterpret_cast<const std::uint8_t*>(check.data());
  EXPECT_EQ(reference_crc32(check_bytes, check.size()), 0xCBF43926u);
  EXPECT_EQ(crc32(check_bytes, check.size()), 0xCBF43926u);
  EXPECT_EQ(crc32(check_bytes + 4, 5, crc32(check_bytes, 4)), 0xCBF43926u);

  const std::size_t covered = image.size() - kImageTrailerSize;
  EXPECT_EQ(get<std::uint32_t>(image, covered), reference_crc32(image.data(), covered));
}

TEST_F(FlashImage, TrailingBytesInTheRegionAreIgnored) {
  Bytes region = image;
  region.resize(image.size() + 1000, 0xFF);  // erased flash
  ImageView view{};
  ASSERT_EQ(parse_image(region.data(), region.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.total_size, image.size());
}

TEST_F(FlashImage, GivenInputRangeIsCarried) {
  // A model fitted on more rows than it carries (a refit, a sparse model)
  // gives the range of all of them.
  model.input_min = Eigen::VectorXd::LinSpaced(4, -2.0, -0.5);
  model.input_max = Eigen::VectorXd::LinSpaced(4, 0.5, 2.0);
  const Bytes ranged = exporting::write_image(model);
  ImageView view{};
  ASSERT_EQ(parse_image(ranged.data(), ranged.size(), view), ImageStatus::ok);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(view.input_min[k], static_cast<float>(model.input_min[k]));
    EXPECT_EQ(view.input_max[k], static_cast<float>(model.input_max[k]));
  }
}

// A sparse model: the points are inducing inputs, the weights beta, and the
// board's sum is the same; only the kind and the rows behind it differ.
TEST_F(FlashImage, SparseModelRoundTrip) {
  training::TrainedModel sparse = model;
  sparse.kind = ImageModelKind::sparse_gp;
  sparse.fitted_rows = 1200;
  sparse.input_min = Eigen::VectorXd::Constant(4, -1.5);
  sparse.input_max = Eigen::VectorXd::Constant(4, 1.5);
  const Bytes sparse_image = exporting::write_image(sparse);
  ASSERT_EQ(sparse_image.size(), image.size());
  EXPECT_EQ(sparse_image[image_field::model_kind.offset], 2);
  EXPECT_EQ(get<std::uint32_t>(sparse_image, layout.metadata_offset + image_metadata_field::fitted_rows), 1200u);

  ImageView view{};
  ASSERT_EQ(parse(sparse_image), ImageStatus::ok);
  ASSERT_EQ(parse_image(sparse_image.data(), sparse_image.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.version_major, 2);
  EXPECT_EQ(view.model_kind, ImageModelKind::sparse_gp);
  EXPECT_EQ(view.training_points, 5u);
  EXPECT_EQ(view.fitted_rows, 1200u);
  EXPECT_EQ(view.input_min[0], -1.5f);
  EXPECT_EQ(view.input_max[3], 1.5f);

  ImageView exact_view{};
  ASSERT_EQ(parse_image(image.data(), image.size(), exact_view), ImageStatus::ok);
  GpCorrection<float, double> sparse_correction;
  GpCorrection<float, double> exact_correction;
  ASSERT_EQ(sparse_correction.bind(view), Status::ok);
  ASSERT_EQ(exact_correction.bind(exact_view), Status::ok);
  const JointVector<float> bend = (JointVector<float>(4) << 0.3f, -0.2f, 0.1f, 0.6f).finished();
  EXPECT_EQ(sparse_correction.predict(bend), exact_correction.predict(bend));
}

// --- version 1 ------------------------------------------------------------------

// Built byte by byte from the v1 specification, not by the exporter.
class FlashImageV1 : public FlashImage {
 protected:
  Bytes v1 = test_support::v1_image(model);
  test_support::V1Layout v1_layout = test_support::v1_layout(5, 4, 2);
};

TEST_F(FlashImageV1, LoadsWithTheSameModel) {
  ASSERT_EQ(v1.size(), image_layout(5, 4, 2, 1).total_size);
  ASSERT_EQ(v1.size() + 4 * 2 * 4, image.size()) << "v2 adds input_min and input_max, D floats each";
  ImageView view{};
  ASSERT_EQ(parse(v1), ImageStatus::ok);
  ASSERT_EQ(parse_image(v1.data(), v1.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.version_major, 1);
  EXPECT_EQ(view.version_minor, 0);
  EXPECT_EQ(view.model_kind, ImageModelKind::exact_gp);
  EXPECT_EQ(view.training_points, 5u);
  EXPECT_EQ(view.fitted_rows, 5u);  // v1 images were fitted on the rows they carry
  EXPECT_EQ(view.input_min, nullptr);
  EXPECT_EQ(view.input_max, nullptr);
  EXPECT_EQ(view.inputs, reinterpret_cast<const float*>(v1.data() + v1_layout.inputs));
  EXPECT_EQ(view.alpha, reinterpret_cast<const float*>(v1.data() + v1_layout.alpha));
  EXPECT_EQ(view.validation_samples, model.validation_samples);
  EXPECT_EQ(std::string(view.trainer, strnlen(view.trainer, 32)), model.trainer);

  // The same float32 model as the v2 image of it, value for value.
  ImageView v2{};
  ASSERT_EQ(parse_image(image.data(), image.size(), v2), ImageStatus::ok);
  EXPECT_EQ(std::memcmp(view.geometry, v2.geometry, 4 * geometry_floats()), 0);
  EXPECT_EQ(std::memcmp(view.input_mean, v2.input_mean, 4 * image_parameter_floats(4, 1)), 0);
  EXPECT_EQ(std::memcmp(view.inputs, v2.inputs, 4 * input_floats()), 0);
  EXPECT_EQ(std::memcmp(view.alpha, v2.alpha, 4 * alpha_floats()), 0);
  GpCorrection<float, double> from_v1;
  GpCorrection<float, double> from_v2;
  ASSERT_EQ(from_v1.bind(view), Status::ok);
  ASSERT_EQ(from_v2.bind(v2), Status::ok);
  const JointVector<float> bend = (JointVector<float>(4) << -0.4f, 0.25f, 0.7f, 0.05f).finished();
  EXPECT_EQ(from_v1.predict(bend), from_v2.predict(bend));
}

TEST_F(FlashImageV1, KeepsItsOwnReservedBytes) {
  // In v1 the bytes v2 gives a meaning are reserved, so a v1 image with a
  // model kind is a bad header, not a sparse model.
  for (std::size_t offset : {29u, 30u, 31u, 56u, 57u, 60u, 61u, 62u, 63u}) {
    Bytes bad = v1;
    bad[offset] = 1;
    test_support::reseal_v1_image(bad);
    EXPECT_EQ(parse_failing(bad, ImageCheckId::header), ImageStatus::bad_header) << offset;
  }
  // Its metadata word at 20 is not looked at.
  Bytes word = v1;
  put<std::uint32_t>(word, v1_layout.metadata + 20, 7);
  test_support::reseal_v1_image(word);
  ImageView view{};
  ASSERT_EQ(parse_image(word.data(), word.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.fitted_rows, 5u);
}

TEST_F(FlashImageV1, IsLaidOutByItsOwnVersion) {
  // v1 bytes labelled v2 lack the input ranges; a v2 image labelled v1 has
  // 32 bytes too many.
  Bytes relabelled = v1;
  put<std::uint16_t>(relabelled, image_field::version_major.offset, 2);
  test_support::reseal_v1_image(relabelled);
  EXPECT_EQ(parse(relabelled), ImageStatus::unsupported_kind) << "v2 reads model_kind 0 first";
  relabelled[image_field::model_kind.offset] = 1;
  test_support::reseal_v1_image(relabelled);
  EXPECT_EQ(parse_failing(relabelled, ImageCheckId::layout), ImageStatus::size_mismatch);

  Bytes v2_as_v1 = image;
  put<std::uint16_t>(v2_as_v1, image_field::version_major.offset, 1);
  v2_as_v1[image_field::model_kind.offset] = 0;
  reseal(v2_as_v1);
  EXPECT_EQ(parse_failing(v2_as_v1, ImageCheckId::layout), ImageStatus::size_mismatch);
}

TEST_F(FlashImageV1, EveryDamagedByteIsRejected) {
  for (std::size_t i = 0; i < v1.size(); ++i) {
    Bytes bad = v1;
    bad[i] ^= 0x01;
    const ImageStatus status = parse(bad);
    ASSERT_NE(status, ImageStatus::ok) << "byte " << i;
    if (i >= 16) {
      ASSERT_EQ(status, ImageStatus::checksum_mismatch) << "byte " << i;
    }
  }
}

// --- every check ------------------------------------------------------------------

// Two independent faults behind a valid CRC: the plain parse stops at the
// first, the reporting parse names both and returns the same status.
TEST_F(FlashImage, ReportingModeFindsEveryIndependentFault) {
  Bytes bad = image;
  bad[image_field::model_kind.offset] = 3;
  put<float>(bad, layout.alpha_offset + 4 * 7, std::numeric_limits<float>::quiet_NaN());
  put<float>(bad, layout.parameters_offset + 4 * (12 + 6 + 1), -1.0f);  // output_scale[1]
  reseal(bad);
  EXPECT_EQ(parse(bad), ImageStatus::unsupported_kind);

  Findings findings;
  ASSERT_EQ(parse_reporting(bad, findings), ImageStatus::unsupported_kind);
  EXPECT_TRUE(findings.failed(ImageCheckId::kind));
  EXPECT_TRUE(findings.failed(ImageCheckId::finite));
  EXPECT_TRUE(findings.failed(ImageCheckId::positive));
  const ImageFinding* nan = findings.failure_of("alpha");
  ASSERT_NE(nan, nullptr);
  EXPECT_EQ(nan->index, 7);
  EXPECT_TRUE(std::isnan(nan->value));
  EXPECT_EQ(nan->status, ImageStatus::non_finite_payload);
  const ImageFinding* scale = findings.failure_of("output_scale");
  ASSERT_NE(scale, nullptr);
  EXPECT_EQ(scale->index, 1);
  EXPECT_EQ(scale->value, -1.0);
  // Nothing else is wrong.
  for (const ImageFinding& f : findings.all) {
    if (f.passed) continue;
    EXPECT_TRUE(f.check == ImageCheckId::kind || f.check == ImageCheckId::finite || f.check == ImageCheckId::positive)
        << to_string(f.check) << " " << f.field;
  }
}

TEST_F(FlashImage, ReportingModeOnAValidImageCoversEveryCheck) {
  Findings findings;
  ASSERT_EQ(parse_reporting(image, findings), ImageStatus::ok);
  for (int c = 0; c < kImageCheckCount; ++c) {
    const auto check = static_cast<ImageCheckId>(c);
    EXPECT_TRUE(std::any_of(findings.all.begin(), findings.all.end(),
                            [check](const ImageFinding& f) { return f.check == check && f.passed; }))
        << to_string(check);
  }
  // Findings arrive in the order of the checks' first evaluation.
  int last = -1;
  std::set<int> seen;
  for (const ImageFinding& f : findings.all) {
    const int c = static_cast<int>(f.check);
    if (seen.insert(c).second) {
      EXPECT_GT(c, last) << to_string(f.check);
      last = c;
    }
  }
}

TEST_F(FlashImage, ReportingModeStaysInsideAShortBuffer) {
  // A header that places the blocks far beyond the buffer: the payload checks
  // are not evaluated rather than read out of bounds (ASan builds see it).
  const Bytes header_only(image.begin(), image.begin() + kImageHeaderSize);
  Findings findings;
  EXPECT_EQ(parse_reporting(header_only, findings), ImageStatus::truncated);
  for (const ImageFinding& f : findings.all) {
    EXPECT_NE(f.check, ImageCheckId::finite);
    EXPECT_NE(f.check, ImageCheckId::checksum);
  }
  EXPECT_TRUE(findings.failed(ImageCheckId::size));
  EXPECT_FALSE(findings.failed(ImageCheckId::layout));

  // A short file still has its magic and version judged.
  Findings short_findings;
  EXPECT_EQ(parse_reporting(Bytes(image.begin(), image.begin() + 6), short_findings), ImageStatus::truncated);
  ASSERT_EQ(short_findings.all.size(), 3u);
  EXPECT_EQ(short_findings.all[1].check, ImageCheckId::magic);
  EXPECT_TRUE(short_findings.all[1].passed);
  EXPECT_EQ(short_findings.all[2].check, ImageCheckId::version);
}

TEST(FlashImageStatus, EveryStatusHasItsOwnMessage) {
  std::set<std::string> messages;
  for (int s = 0; s <= static_cast<int>(ImageStatus::invalid_parameters); ++s) {
    messages.insert(to_string(static_cast<ImageStatus>(s)));
  }
  EXPECT_EQ(messages.size(), static_cast<std::size_t>(ImageStatus::invalid_parameters) + 1);
}

// --- rejections, in the order of the specification's table -------------------

TEST_F(FlashImage, EveryPrefixIsTruncated) {
  for (std::size_t length = 0; length < image.size(); ++length) {
    // An exactly sized copy, so a read past the end is a read past the
    // allocation (visible to sanitizers), not into the rest of the image.
    const Bytes prefix(image.begin(), image.begin() + static_cast<std::ptrdiff_t>(length));
    ASSERT_EQ(parse(prefix), ImageStatus::truncated) << "length " << length;
  }
  ImageView view{};
  EXPECT_EQ(parse_image(nullptr, 0, view), ImageStatus::truncated);
}

TEST_F(FlashImage, BadMagic) {
  for (std::size_t i = 0; i < 4; ++i) {
    Bytes bad = image;
    bad[i] ^= 0x20;  // "cDGP", ...: case matters
    reseal(bad);
    EXPECT_EQ(parse(bad), ImageStatus::bad_magic) << "byte " << i;
  }
}

TEST_F(FlashImage, UnknownMajorVersion) {
  for (std::uint16_t major : {0, 3, 0xFFFF}) {
    Bytes bad = image;
    put<std::uint16_t>(bad, image_field::version_major.offset, major);
    reseal(bad);
    EXPECT_EQ(parse(bad), ImageStatus::unsupported_version) << major;
  }
}

TEST_F(FlashImage, NewerMinorVersionIsAccepted) {
  Bytes newer = image;
  put<std::uint16_t>(newer, image_field::version_minor.offset, 3);
  reseal(newer);
  ImageView view{};
  ASSERT_EQ(parse_image(newer.data(), newer.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.version_minor, 3);
}

TEST_F(FlashImage, WrongHeaderSize) {
  for (std::uint32_t size : {0u, 60u, 65u, 128u}) {
    Bytes bad = image;
    put<std::uint32_t>(bad, image_field::header_size.offset, size);
    reseal(bad);
    EXPECT_EQ(parse(bad), ImageStatus::bad_header) << size;
  }
}

TEST_F(FlashImage, TotalSizeTooSmallForHeaderAndTrailer) {
  for (std::uint32_t total : {0u, 4u, 64u, 67u}) {
    Bytes bad = image;
    put<std::uint32_t>(bad, image_field::total_size.offset, total);
    EXPECT_EQ(parse(bad), ImageStatus::bad_header) << total;
  }
}

TEST_F(FlashImage, TotalSizeBeyondTheBufferIsTruncated) {
  Bytes bad = image;
  put<std::uint32_t>(bad, image_field::total_size.offset, static_cast<std::uint32_t>(image.size() + 8));
  EXPECT_EQ(parse(bad), ImageStatus::truncated);
}

TEST_F(FlashImage, MisalignedBuffer) {
  for (std::size_t shift = 1; shift < 8; ++shift) {
    Bytes shifted(image.size() + shift);
    std::memcpy(shifted.data() + shift, image.data(), image.size());
    ImageView view{};
    const ImageStatus status = parse_image(shifted.data() + shift, image.size(), view);
    // 4-byte alignment is what float access needs; 8 is only preferred.
    EXPECT_EQ(status, shift % 4 == 0 ? ImageStatus::ok : ImageStatus::misaligned) << "shift " << shift;
  }
}

TEST_F(FlashImage, EveryDamagedByteIsRejected) {
  for (std::size_t i = 0; i < image.size(); ++i) {
    for (std::uint8_t mask : {std::uint8_t{0x01}, std::uint8_t{0x80}, std::uint8_t{0xFF}}) {
      Bytes bad = image;
      bad[i] ^= mask;
      const ImageStatus status = parse(bad);
      ASSERT_NE(status, ImageStatus::ok) << "byte " << i << " ^ " << int(mask);
      // Beyond magic, version_major, header_size and total_size the CRC is
      // the first check that can see the damage.
      if (i >= 16) {
        ASSERT_EQ(status, ImageStatus::checksum_mismatch) << "byte " << i << " ^ " << int(mask);
      }
    }
  }
}

TEST_F(FlashImage, ReservedHeaderBytesMustBeZero) {
  for (std::size_t offset : {image_field::compliance_segments.offset, image_field::hysteresis_cables.offset, image_field::hysteresis_operators.offset}) {
    Bytes bad = image;
    bad[offset] = 1;
    EXPECT_EQ(parse(bad), ImageStatus::checksum_mismatch) << offset;
    reseal(bad);
    EXPECT_EQ(parse_failing(bad, ImageCheckId::header), ImageStatus::bad_header) << offset;
    Findings findings;
    parse_reporting(bad, findings);
    ASSERT_NE(findings.failure_of("reserved"), nullptr);
    EXPECT_EQ(findings.failure_of("reserved")->index, static_cast<std::int32_t>(offset));
  }
}

// A v2.0 image has no variance block (2.1 defines it): one that claims one
// is refused, not half-read.
TEST_F(FlashImage, VarianceFactorFieldsMustBeZeroInVersion20) {
  for (std::size_t byte = 0; byte < 6; ++byte) {
    Bytes bad = image;
    bad[image_field::version_minor.offset] = 0;
    bad[image_field::version_minor.offset + 1] = 0;
    bad[image_field::variance_offset.offset + byte] = 8;
    reseal(bad);
    EXPECT_EQ(parse_failing(bad, ImageCheckId::header), ImageStatus::bad_header) << "byte " << byte;
    Findings findings;
    parse_reporting(bad, findings);
    const ImageFinding* failure = findings.failure_of(byte < 4 ? "variance_offset" : "variance_rank");
    ASSERT_NE(failure, nullptr) << byte;
    EXPECT_EQ(failure->value, 8.0 * (1u << (8 * (byte % 4)))) << byte;
    EXPECT_EQ(failure->expected, 0.0);
    EXPECT_EQ(failure->status, ImageStatus::bad_header);
  }
}

TEST_F(FlashImage, UnknownModelKindOrExtraInputs) {
  const std::pair<std::size_t, std::uint8_t> cases[] = {{image_field::model_kind.offset, 0},
                                                        {image_field::model_kind.offset, 3},
                                                        {image_field::model_kind.offset, 0xFF},
                                                        {image_field::extra_inputs.offset, 2},
                                                        {image_field::extra_inputs.offset, 0xFF}};
  for (const auto& [offset, value] : cases) {
    Bytes bad = image;
    bad[offset] = value;
    reseal(bad);
    EXPECT_EQ(parse_failing(bad, ImageCheckId::kind), ImageStatus::unsupported_kind) << offset << " = " << int(value);
    Findings findings;
    parse_reporting(bad, findings);
    const ImageFinding* failure =
        findings.failure_of(offset == image_field::model_kind.offset ? "model_kind" : "extra_inputs");
    ASSERT_NE(failure, nullptr);
    EXPECT_EQ(failure->value, value);
  }
}

// extra_inputs 1 (the payload) widens D by one and the parameters block by
// its default: a header that says so over a joint-only image's dims or
// blocks is inconsistent, not unsupported.
TEST_F(FlashImage, OnePayloadInputNeedsItsDimsAndBlocks) {
  Bytes bad = image;
  bad[image_field::extra_inputs.offset] = 1;
  reseal(bad);
  EXPECT_EQ(parse_failing(bad, ImageCheckId::header), ImageStatus::bad_header);
  put<std::uint16_t>(bad, image_field::input_dims.offset, 5);
  reseal(bad);
  EXPECT_EQ(parse_failing(bad, ImageCheckId::layout), ImageStatus::size_mismatch);
}

// A payload model: D = 2n + 1, the payload's range among the inputs', and
// the default payload after input_max.
TEST_F(FlashImage, PayloadModelRoundTrip) {
  test_support::SyntheticModelOptions options;
  options.payload_input = true;
  const training::TrainedModel payload_model = test_support::synthetic_trained_model(options);
  const Bytes payload_image = exporting::write_image(payload_model);
  const ImageLayout expected = image_layout(5, 5, 2, kImageVersionMajor, 0, 1);
  ASSERT_EQ(payload_image.size(), expected.total_size);
  // One float more in the parameters than a 5-input model without the payload.
  EXPECT_EQ(image_parameter_floats(5, kImageVersionMajor, 1), image_parameter_floats(5) + 1);
  ImageView view{};
  ASSERT_EQ(parse(payload_image), ImageStatus::ok);
  ASSERT_EQ(parse_image(payload_image.data(), payload_image.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.extra_inputs, 1);
  EXPECT_EQ(view.input_dims, 5);
  EXPECT_EQ(view.segment_count, 2);
  ASSERT_NE(view.extra_input_default, nullptr);
  EXPECT_EQ(*view.extra_input_default, 0.375f);
  EXPECT_EQ(get<std::uint8_t>(payload_image, image_field::extra_inputs.offset), 1);
  EXPECT_EQ(view.extra_input_default, view.input_max + 5);
  EXPECT_EQ(view.input_min[4], static_cast<float>(payload_model.inputs.col(4).minCoeff()));
  EXPECT_EQ(view.input_max[4], static_cast<float>(payload_model.inputs.col(4).maxCoeff()));
  // An image without the input has no default.
  ImageView joint_only{};
  ASSERT_EQ(parse_image(image.data(), image.size(), joint_only), ImageStatus::ok);
  EXPECT_EQ(joint_only.extra_inputs, 0);
  EXPECT_EQ(joint_only.extra_input_default, nullptr);

  // A negative default is no mass.
  Bytes bad = payload_image;
  const std::size_t default_offset =
      expected.parameters_offset + 4 * (image_parameter_floats(5, kImageVersionMajor, 1) - 1);
  put<float>(bad, default_offset, -0.25f);
  reseal(bad);
  EXPECT_EQ(parse_failing(bad, ImageCheckId::ranges), ImageStatus::invalid_parameters);
  put<float>(bad, default_offset, std::numeric_limits<float>::quiet_NaN());
  reseal(bad);
  EXPECT_EQ(parse_failing(bad, ImageCheckId::finite), ImageStatus::non_finite_payload);
  // A build without room for the extra input refuses it.
  ImageCapacity no_extra;
  no_extra.max_extra_inputs = 0;
  EXPECT_EQ(parse_failing(payload_image, ImageCheckId::capacity, no_extra), ImageStatus::over_capacity);
}

TEST_F(FlashImage, UnsupportedScalarKernelOrEncoding) {
  const std::pair<std::size_t, std::uint8_t> cases[] = {
      {image_field::scalar_type.offset, 0},    {image_field::scalar_type.offset, 2},  {image_field::kernel_kind.offset, 0},
      {image_field::kernel_kind.offset, 2},    {image_field::input_encoding.offset, 0}, {image_field::input_encoding.offset, 3},
      {image_field::input_encoding.offset, 0xFF}};
  for (const auto& [offset, value] : cases) {
    Bytes bad = image;
    bad[offset] = value;
    reseal(bad);
    EXPECT_EQ(parse(bad), ImageStatus::unsupported_kind) << offset << " = " << int(value);
  }
}

TEST_F(FlashImage, InconsistentDims) {
  const auto edit = [this](std::size_t offset, std::uint32_t value, bool wide) {
    Bytes bad = image;
    if (wide) {
      put<std::uint32_t>(bad, offset, value);
    } else {
      put<std::uint16_t>(bad, offset, static_cast<std::uint16_t>(value));
    }
    reseal(bad);
    return parse(bad);
  };
  EXPECT_EQ(edit(image_field::training_points.offset, 0, true), ImageStatus::bad_header);
  EXPECT_EQ(edit(image_field::segment_count.offset, 0, false), ImageStatus::bad_header);
  EXPECT_EQ(edit(image_field::input_dims.offset, 5, false), ImageStatus::bad_header);
  EXPECT_EQ(edit(image_field::input_dims.offset, 0, false), ImageStatus::bad_header);
  EXPECT_EQ(edit(image_field::segment_count.offset, 3, false), ImageStatus::bad_header);
  EXPECT_EQ(edit(image_field::output_dims.offset, 5, false), ImageStatus::bad_header);
  EXPECT_EQ(edit(image_field::output_dims.offset, 7, false), ImageStatus::bad_header);
}

TEST_F(FlashImage, OverCapacity) {
  EXPECT_EQ(parse(image, ImageCapacity{5, 2}), ImageStatus::ok);
  EXPECT_EQ(parse(image, ImageCapacity{4, 8}), ImageStatus::over_capacity);
  EXPECT_EQ(parse(image, ImageCapacity{1024, 1}), ImageStatus::over_capacity);
  EXPECT_EQ(parse(image, ImageCapacity{0, 0}), ImageStatus::over_capacity);
}

TEST_F(FlashImage, MisalignedBlockOffset) {
  for (std::size_t field : {image_field::geometry_offset.offset, image_field::parameters_offset.offset, image_field::inputs_offset.offset,
                            image_field::alpha_offset.offset, image_field::metadata_offset.offset}) {
    for (std::uint32_t shift : {1u, 4u}) {
      Bytes bad = image;
      put<std::uint32_t>(bad, field, get<std::uint32_t>(bad, field) + shift);
      reseal(bad);
      EXPECT_EQ(parse(bad), ImageStatus::misaligned) << "field " << field << " + " << shift;
    }
  }
}

TEST_F(FlashImage, OffsetOrSizeDisagreeingWithTheDims) {
  for (std::size_t field : {image_field::geometry_offset.offset, image_field::parameters_offset.offset, image_field::inputs_offset.offset,
                            image_field::alpha_offset.offset, image_field::metadata_offset.offset}) {
    for (std::int64_t shift : {-8, 8}) {
      Bytes bad = image;
      put<std::uint32_t>(bad, field, static_cast<std::uint32_t>(get<std::uint32_t>(bad, field) + shift));
      reseal(bad);
      EXPECT_EQ(parse(bad), ImageStatus::size_mismatch) << "field " << field << " " << shift;
    }
  }
  {
    Bytes bad = image;
    put<std::uint32_t>(bad, image_field::metadata_size.offset, kImageMetadataSize + 8);
    reseal(bad);
    EXPECT_EQ(parse(bad), ImageStatus::size_mismatch) << "metadata_size";
  }
  {
    // A consistent-looking image eight bytes longer than its dims imply.
    Bytes longer = image;
    longer.insert(longer.end() - kImageTrailerSize, 8, 0);
    put<std::uint32_t>(longer, image_field::total_size.offset, static_cast<std::uint32_t>(longer.size()));
    reseal(longer);
    EXPECT_EQ(parse(longer), ImageStatus::size_mismatch) << "total_size";
  }
  {
    // One training point fewer: the arrays no longer fill the blocks.
    Bytes bad = image;
    put<std::uint32_t>(bad, image_field::training_points.offset, 4);
    reseal(bad);
    EXPECT_EQ(parse(bad), ImageStatus::size_mismatch) << "training_points";
  }
}

TEST_F(FlashImage, DimsThatWrapTheLayoutArithmeticAreASizeMismatch) {
  // N + 2^29 points of 4 inputs and 6 outputs add 2^29 * 40 bytes = 5 * 2^32:
  // in 32-bit arithmetic the very same layout. A parser given room for such
  // an N must not trust the wrapped sizes and read past the image.
  Bytes bad = image;
  put<std::uint32_t>(bad, image_field::training_points.offset, 5u + (1u << 29));
  reseal(bad);
  const ImageCapacity unlimited{std::numeric_limits<std::uint32_t>::max(), std::numeric_limits<std::uint16_t>::max()};
  EXPECT_EQ(parse(bad, unlimited), ImageStatus::size_mismatch);
  EXPECT_EQ(parse(bad), ImageStatus::over_capacity);
}

TEST_F(FlashImage, NonFinitePayload) {
  struct Block {
    const char* name;
    std::uint32_t offset;
    std::uint32_t floats;
  };
  const Block blocks[] = {{"geometry", 64, geometry_floats()},
                          {"parameters", layout.parameters_offset, parameter_floats()},
                          {"inputs", layout.inputs_offset, input_floats()},
                          {"alpha", layout.alpha_offset, alpha_floats()}};
  const float poisons[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                           -std::numeric_limits<float>::infinity()};
  for (const Block& block : blocks) {
    for (std::uint32_t i = 0; i < block.floats; ++i) {
      for (float poison : poisons) {
        Bytes bad = image;
        put<float>(bad, block.offset + 4 * i, poison);
        reseal(bad);
        ASSERT_EQ(parse(bad), ImageStatus::non_finite_payload) << block.name << "[" << i << "] = " << poison;
      }
    }
  }
}

TEST_F(FlashImage, NonFiniteInputRangeIsNonFinitePayload) {
  const std::uint32_t ranges = layout.parameters_offset + 4 * (3 * 4 + 4 * kImageOutputs);
  for (std::uint32_t i = 0; i < 2 * 4; ++i) {
    for (float poison : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
      Bytes bad = image;
      put<float>(bad, ranges + 4 * i, poison);
      reseal(bad);
      EXPECT_EQ(parse_failing(bad, ImageCheckId::finite), ImageStatus::non_finite_payload) << i << " = " << poison;
    }
  }
}

TEST_F(FlashImage, InvertedInputRange) {
  const std::uint32_t input_min = layout.parameters_offset + 4 * (3 * 4 + 4 * kImageOutputs);
  const std::uint32_t input_max = input_min + 4 * 4;
  for (std::uint32_t k = 0; k < 4; ++k) {
    Bytes bad = image;
    const float low = get<float>(bad, input_min + 4 * k);
    const float high = get<float>(bad, input_max + 4 * k);
    put<float>(bad, input_min + 4 * k, high);
    put<float>(bad, input_max + 4 * k, low);
    reseal(bad);
    EXPECT_EQ(parse_failing(bad, ImageCheckId::ranges), ImageStatus::invalid_parameters) << k;
    Findings findings;
    parse_reporting(bad, findings);
    const ImageFinding* failure = findings.failure_of("input_min");
    ASSERT_NE(failure, nullptr);
    EXPECT_EQ(failure->index, static_cast<std::int32_t>(k));
    EXPECT_EQ(failure->value, high);
    EXPECT_EQ(failure->expected, low);
  }
  // An empty range, every row alike in one input, is a range.
  Bytes point = image;
  put<float>(point, input_max, get<float>(point, input_min));
  reseal(point);
  EXPECT_EQ(parse(point), ImageStatus::ok);
}

TEST_F(FlashImage, FittedRows) {
  const std::size_t fitted_rows = layout.metadata_offset + image_metadata_field::fitted_rows;
  for (std::uint32_t rows : {0u, 4u, 6u, 1000u}) {
    Bytes bad = image;
    put<std::uint32_t>(bad, fitted_rows, rows);
    reseal(bad);
    // An exact model's rows are its points.
    EXPECT_EQ(parse_failing(bad, ImageCheckId::fitted_rows), ImageStatus::invalid_parameters) << rows;
  }
  Bytes sparse = image;
  sparse[image_field::model_kind.offset] = static_cast<std::uint8_t>(ImageModelKind::sparse_gp);
  for (std::uint32_t rows : {1u, 4u, 6u, 1000u}) {
    put<std::uint32_t>(sparse, fitted_rows, rows);
    reseal(sparse);
    ImageView view{};
    ASSERT_EQ(parse_image(sparse.data(), sparse.size(), view), ImageStatus::ok) << rows;
    EXPECT_EQ(view.fitted_rows, rows);
  }
  put<std::uint32_t>(sparse, fitted_rows, 0);
  reseal(sparse);
  EXPECT_EQ(parse_failing(sparse, ImageCheckId::fitted_rows), ImageStatus::invalid_parameters);
}

TEST_F(FlashImage, MetadataMetricsAreNotPayload) {
  Bytes informational = image;
  put<float>(informational, layout.metadata_offset + image_metadata_field::metrics,
             std::numeric_limits<float>::quiet_NaN());
  reseal(informational);
  EXPECT_EQ(parse(informational), ImageStatus::ok);
}

TEST_F(FlashImage, NonPositiveParameters) {
  const std::uint32_t p = layout.parameters_offset;
  std::vector<std::pair<std::string, std::uint32_t>> must_be_positive;
  for (std::uint32_t i = 0; i < geometry_floats(); ++i) must_be_positive.emplace_back("geometry", 64 + 4 * i);
  for (std::uint32_t i = 0; i < 4; ++i) {
    must_be_positive.emplace_back("input_scale", p + 4 * (4 + i));
    must_be_positive.emplace_back("length_scale", p + 4 * (8 + i));
  }
  for (std::uint32_t k = 0; k < 6; ++k) {
    must_be_positive.emplace_back("output_scale", p + 4 * (12 + 6 + k));
    must_be_positive.emplace_back("signal_variance", p + 4 * (12 + 12 + k));
    must_be_positive.emplace_back("noise_variance", p + 4 * (12 + 18 + k));
  }
  for (const auto& [name, offset] : must_be_positive) {
    for (float value : {0.0f, -0.0f, -1.0f, -std::numeric_limits<float>::denorm_min()}) {
      Bytes bad = image;
      put<float>(bad, offset, value);
      reseal(bad);
      ASSERT_EQ(parse(bad), ImageStatus::invalid_parameters) << name << " at " << offset << " = " << value;
    }
  }
  // Means and alpha carry a sign.
  for (std::uint32_t offset : {p, p + 4 * 12, layout.alpha_offset}) {
    Bytes negative = image;
    put<float>(negative, offset, -get<float>(negative, offset) - 1.0f);
    reseal(negative);
    EXPECT_EQ(parse(negative), ImageStatus::ok) << offset;
  }
}

TEST_F(FlashImage, WriterRefusesWhatTheParserWouldRefuse) {
  training::TrainedModel bad = model;
  bad.length_scales[1] = 0.0;
  EXPECT_THROW(exporting::write_image(bad), std::invalid_argument);
  bad = model;
  bad.noise_variance[2] = 1e-50;  // positive in double, zero in float32
  EXPECT_THROW(exporting::write_image(bad), std::invalid_argument);
  bad = model;
  bad.alpha(0, 0) = 1e39;  // beyond float32
  EXPECT_THROW(exporting::write_image(bad), std::invalid_argument);
  bad = model;
  bad.alpha.conservativeResize(4, 6);
  EXPECT_THROW(exporting::write_image(bad), std::invalid_argument);
  bad = model;
  bad.geometry.segment_count = 1;
  EXPECT_THROW(exporting::write_image(bad), std::invalid_argument);
  bad = model;
  bad.set_input_range(bad.inputs);
  std::swap(bad.input_min[2], bad.input_max[2]);
  EXPECT_THROW(exporting::write_image(bad), std::invalid_argument);
  bad = model;
  bad.input_min = Eigen::VectorXd::Zero(3);
  bad.input_max = Eigen::VectorXd::Ones(3);
  EXPECT_THROW(exporting::write_image(bad), std::invalid_argument);
  bad = model;
  bad.fitted_rows = 6;  // an exact model of 5 points
  EXPECT_THROW(exporting::write_image(bad), std::invalid_argument);
  bad = model;
  bad.kind = ImageModelKind::sparse_gp;  // without the rows behind it
  EXPECT_THROW(exporting::write_image(bad), std::invalid_argument);
}

// The trainer records the range of every row a model is fitted on: the
// search's rows, then all rows when the exported model is refitted on them.
TEST(TrainerInputRange, IsTheRangeOfTheRowsTheModelIsFittedOn) {
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 0.3);
  training::TrainingSet all;
  all.inputs = Eigen::MatrixXd::NullaryExpr(12, 4, [&] { return normal(rng); });
  all.error_twists = Eigen::MatrixXd::NullaryExpr(12, 6, [&] { return normal(rng); });
  all.inputs.row(11) << 2.0, -2.0, 2.5, -2.5;  // extremes only in the rows the search does not see
  training::TrainingSet searched;
  searched.inputs = all.inputs.topRows(8);
  searched.error_twists = all.error_twists.topRows(8);

  training::TrainingOptions options;
  options.search.restarts = 0;
  const auto geometry = RobotGeometry<double>::uniform(2, 120.0, 67.0);
  const training::TrainedModel trained = training::train(searched, geometry, options);
  EXPECT_EQ(trained.input_min, Eigen::VectorXd(searched.inputs.colwise().minCoeff().transpose()));
  EXPECT_EQ(trained.input_max, Eigen::VectorXd(searched.inputs.colwise().maxCoeff().transpose()));

  const training::TrainedModel refitted = training::refit(trained, training::ModelKind::exact, all);
  EXPECT_EQ(refitted.input_min, Eigen::VectorXd(all.inputs.colwise().minCoeff().transpose()));
  EXPECT_EQ(refitted.input_max, Eigen::VectorXd(all.inputs.colwise().maxCoeff().transpose()));
  const Bytes image = exporting::write_image(refitted);
  ImageView view{};
  ASSERT_EQ(parse_image(image.data(), image.size(), view), ImageStatus::ok);
  EXPECT_EQ(view.fitted_rows, 12u);
  EXPECT_EQ(view.input_max[0], 2.0f);
  EXPECT_EQ(view.input_min[3], -2.5f);
}

// --- the float32 run time against the double-precision trainer ----------------

template <typename Accumulator>
void expect_runtime_matches_trainer(InputEncoding encoding) {
  test_support::SyntheticModelOptions options;
  options.encoding = encoding;
  options.training_points = 40;
  const training::TrainedModel model = test_support::synthetic_trained_model(options);
  const Bytes image = exporting::write_image(model);
  ImageView view{};
  ASSERT_EQ(parse_image(image.data(), image.size(), view), ImageStatus::ok);
  GpCorrection<float, Accumulator> correction;
  ASSERT_EQ(correction.bind(view), Status::ok);

  std::mt19937 rng(7);
  std::uniform_real_distribution<double> alpha_rad(-3.0, 3.0);
  std::uniform_real_distribution<double> theta_rad(0.05, 1.2);
  constexpr int kQueries = 200;
  Eigen::MatrixXd bends(kQueries, 4);
  for (int q = 0; q < kQueries; ++q) {
    for (int s = 0; s < 2; ++s) {
      const double a = alpha_rad(rng);
      const double t = theta_rad(rng);
      bends(q, 2 * s) = t * std::cos(a);
      bends(q, 2 * s + 1) = t * std::sin(a);
    }
  }
  const Eigen::MatrixXd expected = training::predict_error_twists(model, bends);

  double worst_relative = 0.0;
  for (int q = 0; q < kQueries; ++q) {
    const JointVector<float> bend = bends.row(q).transpose().cast<float>();
    const Twist<float> eps = correction.predict(bend);
    Twist<float> eps_with_gradient;
    Jacobian<float> gradient;
    ASSERT_EQ(correction(bend, eps_with_gradient, gradient), Status::ok);
    for (int k = 0; k < 6; ++k) {
      // The GP sum before output scaling is what float32 rounds; measure
      // against its scale.
      const double scale = model.output_scale[k] * model.signal_variance[k] + std::abs(model.output_mean[k]);
      const double relative = std::abs(eps[k] - expected(q, k)) / scale;
      worst_relative = std::max(worst_relative, relative);
      EXPECT_EQ(eps[k], eps_with_gradient[k]);
    }
  }
  // float32 inputs, kernel coordinates and alpha: a few ulps (6e-8) per term.
  EXPECT_LT(worst_relative, 2e-6);
  std::cout << "[          ] worst relative difference, " << to_string(encoding) << ": " << worst_relative << "\n";
}

TEST(FlashImageRuntime, FloatPredictionMatchesTrainerWithDoubleAccumulator) {
  expect_runtime_matches_trainer<double>(InputEncoding::bend_vector);
  expect_runtime_matches_trainer<double>(InputEncoding::joint_angles);
}

TEST(FlashImageRuntime, FloatPredictionMatchesTrainerWithCompensatedFloatAccumulator) {
  expect_runtime_matches_trainer<CompensatedFloat>(InputEncoding::bend_vector);
  expect_runtime_matches_trainer<CompensatedFloat>(InputEncoding::joint_angles);
}

}  // namespace
}  // namespace cdcr::model

namespace cdcr::model {
namespace {

// A damaged rank whose block size would wrap a 32-bit count: both modes
// refuse it, and the reporting mode reads nothing outside the image (the
// fuzzer found the wrap; under ASan this test fails without the fix).
TEST_F(FlashImage, AHugeVarianceRankIsRefusedWithoutReadingPastTheImage) {
  for (const std::uint16_t rank : {std::uint16_t{65535}, std::uint16_t{65534}, std::uint16_t{4096}}) {
    Bytes bad = image;
    std::memcpy(bad.data() + image_field::variance_rank.offset, &rank, 2);
    reseal(bad);
    EXPECT_NE(parse(bad, ImageCapacity{1024, 8, 65535}), ImageStatus::ok) << rank;
    EXPECT_EQ(parse(bad), ImageStatus::over_capacity) << rank;
  }
}

// --- the whole-image checks scanned a slice at a time ---------------------------

// The parse takes the CRC and the finite payload from the scan: it reads no
// payload again, so bytes changed after the scan go unseen (what keeps the
// firmware's parse of a scanned image short). Without the scan they are.
TEST_F(FlashImage, AScannedParseTakesTheScansVerdicts) {
  Bytes changed = image;
  ImageScan scan;
  scan.begin(changed.data(), changed.size());
  while (!scan.step(64)) {
  }
  put<float>(changed, layout.inputs_offset, std::numeric_limits<float>::quiet_NaN());
  ImageView view{};
  EXPECT_EQ(parse_image(changed.data(), changed.size(), view, ImageCapacity{}, scan), ImageStatus::ok);
  EXPECT_EQ(parse_image(changed.data(), changed.size(), view, ImageCapacity{}), ImageStatus::checksum_mismatch);
}

// A scan of other bytes, or one not finished, is not used.
TEST_F(FlashImage, AScanOfOtherBytesOrUnfinishedIsNotUsed) {
  Bytes bad = image;
  put<float>(bad, layout.alpha_offset + 4, std::numeric_limits<float>::infinity());
  reseal(bad);
  ImageScan of_image;
  of_image.begin(image.data(), image.size());
  while (!of_image.step(1024)) {
  }
  ImageView view{};
  EXPECT_EQ(parse_image(bad.data(), bad.size(), view, ImageCapacity{}, of_image), ImageStatus::non_finite_payload);

  Bytes damaged = image;
  damaged[layout.inputs_offset + 1] ^= 0x10;
  ImageScan half;
  half.begin(damaged.data(), damaged.size());
  half.step(static_cast<std::uint32_t>(damaged.size() / 2) & ~3u);
  ASSERT_FALSE(half.done());
  EXPECT_EQ(parse_image(damaged.data(), damaged.size(), view, ImageCapacity{}, half), ImageStatus::checksum_mismatch);
}

}  // namespace
}  // namespace cdcr::model
