// Motion-capture import: QTM 6DOF TSV files written here from known base and
// end-platform poses in the camera frame must give back the end platform in
// the base frame (eq. 21); damaged captures must be refused with the line.

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "cli_errors.hpp"
#include "dataset/csv_dataset.hpp"
#include "dataset/mocap_import.hpp"
#include "import_mocap_command.hpp"
#include "rejection_case.hpp"

#include "../../support/run_cdcr.hpp"

namespace {

using cdcr::dataset::Dataset;
using cdcr::dataset::DatasetError;
using cdcr::dataset::LostFrames;
using cdcr::dataset::MocapCapture;
using cdcr::dataset::MocapImport;
using cdcr::dataset::MocapImportOptions;
using Pose = cdcr::model::Pose<double>;
using OptionalPose = std::optional<Pose>;

// ---------------------------------------------------------------------------
// Writing QTM-style files.

struct BodyTrack {
  std::string name;
  std::vector<OptionalPose> in_camera;  // one per frame; empty = not tracked
};

enum class LostStyle { nan, zeros };

struct TsvStyle {
  bool full_precision = true;  // %.17g; otherwise QTM's 5 decimals
  LostStyle lost = LostStyle::nan;
  bool crlf = false;
  bool timecode_column = false;
};

std::string number(double value, bool full_precision) {
  char text[64];
  std::snprintf(text, sizeof text, full_precision ? "%.17g" : "%.5f", value);
  return text;
}

std::string qtm_tsv(const std::vector<BodyTrack>& bodies, const TsvStyle& style = {}) {
  const std::size_t frames = bodies.front().in_camera.size();
  std::string names;
  for (const BodyTrack& b : bodies) names += "\t" + b.name;
  std::string text = "NO_OF_FRAMES\t" + std::to_string(frames) +
                     "\nNO_OF_CAMERAS\t6\nNO_OF_BODIES\t" + std::to_string(bodies.size()) +
                     "\nFREQUENCY\t100\nNO_OF_ANALOG\t0\nANALOG_FREQUENCY\t0\nDESCRIPTION\t--\n"
                     "TIME_STAMP\t2020-03-01, 10:00:00\t1234.5678\nDATA_INCLUDED\t6D\nBODY_NAMES" +
                     names + "\nFrame\tTime\t";
  if (style.timecode_column) text += "SMPTE\t";
  for (const BodyTrack& b : bodies) {
    text += b.name + " X\tY\tZ\tRoll\tPitch\tYaw\tResidual";
    for (int k = 0; k < 9; ++k) text += "\tRot[" + std::to_string(k) + "]";
    text += "\t";
  }
  text += "\n";
  for (std::size_t f = 0; f < frames; ++f) {
    text += std::to_string(f + 1) + "\t" + number(0.01 * static_cast<double>(f), false) + "\t";
    if (style.timecode_column) text += "10:00:00:" + std::to_string(f) + "\t";
    for (const BodyTrack& b : bodies) {
      const OptionalPose& pose = b.in_camera[f];
      if (!pose) {
        const std::string lost = style.lost == LostStyle::nan ? "NaN" : "0.00000";
        for (int k = 0; k < 16; ++k) text += lost + "\t";
        continue;
      }
      const Eigen::Vector3d angles_deg = pose->rotation.eulerAngles(0, 1, 2) * 180.0 / M_PI;
      for (int i = 0; i < 3; ++i) text += number(pose->position_mm[i], style.full_precision) + "\t";
      for (int i = 0; i < 3; ++i) text += number(angles_deg[i], false) + "\t";
      text += "0.84210\t";
      for (int k = 0; k < 9; ++k) text += number(pose->rotation(k % 3, k / 3), style.full_precision) + "\t";
    }
    text += "\n";
  }
  if (style.crlf) {
    std::string crlf;
    for (const char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    return crlf;
  }
  return text;
}

Dataset commanded_cables(int rows, int segments = 2) {
  Dataset data;
  data.segment_count = segments;
  data.cables_mm.resize(rows, 4 * segments);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < 4 * segments; ++c) data.cables_mm(r, c) = 100.0 + r + 0.25 * c;
  }
  return data;
}

// Signed permutation matrices with determinant +1: the 24 rotations of a cube.
// Their products and inverses are exact in floating point.
std::vector<Eigen::Matrix3d> cube_rotations() {
  std::vector<Eigen::Matrix3d> rotations;
  const int permutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& p : permutations) {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d r = Eigen::Matrix3d::Zero();
      for (int i = 0; i < 3; ++i) r(i, p[i]) = (signs >> i) & 1 ? -1.0 : 1.0;
      if (r.determinant() > 0) rotations.push_back(r);
    }
  }
  return rotations;
}

Pose random_pose(std::mt19937_64& rng, double spread_mm) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::Quaterniond q(gauss(rng), gauss(rng), gauss(rng), gauss(rng));
  q.normalize();
  return Pose{q.toRotationMatrix(), spread_mm * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng))};
}

MocapImportOptions bodies(const std::string& base, const std::string& end, LostFrames lost = LostFrames::reject) {
  MocapImportOptions options;
  options.base_body = base;
  options.end_body = end;
  options.lost_frames = lost;
  return options;
}

DatasetError tsv_rejection(const std::string& text) {
  return cdcr::test_support::refusal([&] { cdcr::dataset::parse_qtm_6d_tsv(text); }, text);
}

DatasetError import_rejection(const Dataset& commanded, const std::string& text, const MocapImportOptions& options) {
  const MocapCapture capture = cdcr::dataset::parse_qtm_6d_tsv(text);
  return cdcr::test_support::refusal([&] { cdcr::dataset::import_mocap(commanded, capture, options); }, text,
                                     "imported");
}

// A file with base and end bodies whose end-in-base poses are known.
struct KnownCapture {
  std::vector<Pose> end_in_base;
  BodyTrack base{"Base", {}};
  BodyTrack end{"End platform", {}};
};

KnownCapture known_capture(int frames, unsigned seed) {
  std::mt19937_64 rng(seed);
  KnownCapture k;
  for (int f = 0; f < frames; ++f) {
    const Pose base = random_pose(rng, 1500.0);
    const Pose relative{random_pose(rng, 0.0).rotation, Eigen::Vector3d(20.0 * f, -15.0, 450.0 + f)};
    k.end_in_base.push_back(relative);
    k.base.in_camera.push_back(base);
    k.end.in_camera.push_back(base * relative);
  }
  return k;
}

// ---------------------------------------------------------------------------
// Eq. (21) and the file layout.

TEST(MocapImport, RecoversExactRelativePoses) {
  const std::vector<Eigen::Matrix3d> rotations = cube_rotations();
  ASSERT_EQ(rotations.size(), 24u);
  BodyTrack base{"Base", {}};
  BodyTrack end{"Tip", {}};
  std::vector<Pose> expected;
  for (std::size_t i = 0; i < rotations.size(); ++i) {
    const Pose base_in_camera{rotations[i], Eigen::Vector3d(1000.0 - 17.0 * i, -250.0, 1500.0 + 3.0 * i)};
    const Pose end_in_base{rotations[(7 * i + 3) % 24], Eigen::Vector3d(12.0, -7.0 + i, 480.0)};
    base.in_camera.push_back(base_in_camera);
    end.in_camera.push_back(base_in_camera * end_in_base);
    expected.push_back(end_in_base);
  }
  const MocapImport result = cdcr::dataset::import_mocap(
      commanded_cables(24), cdcr::dataset::parse_qtm_6d_tsv(qtm_tsv({base, end})), bodies("Base", "Tip"));
  ASSERT_EQ(result.data.poses.size(), 24u);
  EXPECT_TRUE(result.skipped_frames.empty());
  EXPECT_TRUE(result.data.has_poses);
  EXPECT_EQ(result.data.cables_mm, commanded_cables(24).cables_mm);
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(result.data.poses[i].rotation, expected[i].rotation) << i;
    EXPECT_EQ(result.data.poses[i].position_mm, expected[i].position_mm) << i;
  }
}

TEST(MocapImport, RecoversGeneralRelativePosesToRoundOff) {
  const KnownCapture k = known_capture(50, 11);
  const MocapImport result = cdcr::dataset::import_mocap(
      commanded_cables(50), cdcr::dataset::parse_qtm_6d_tsv(qtm_tsv({k.base, k.end})), bodies("Base", "End platform"));
  ASSERT_EQ(result.data.poses.size(), 50u);
  for (std::size_t i = 0; i < 50; ++i) {
    EXPECT_LE((result.data.poses[i].rotation - k.end_in_base[i].rotation).cwiseAbs().maxCoeff(), 1e-14) << i;
    EXPECT_LE((result.data.poses[i].position_mm - k.end_in_base[i].position_mm).cwiseAbs().maxCoeff(), 1e-9) << i;
  }
}

TEST(MocapImport, EndInBaseIsEquation21) {
  std::mt19937_64 rng(5);
  const Pose base = random_pose(rng, 800.0);
  const Pose end = random_pose(rng, 800.0);
  const Pose relative = cdcr::dataset::end_in_base(base, end);
  const Eigen::Matrix4d expected = base.matrix().inverse() * end.matrix();
  EXPECT_LE((relative.matrix() - expected).cwiseAbs().maxCoeff(), 1e-12);
  // Swapping the bodies gives the inverse, not the same pose.
  EXPECT_LE(((cdcr::dataset::end_in_base(end, base) * relative).matrix() - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff(),
            1e-12);
}

TEST(MocapImport, RotationColumnsAreColumnMajor) {
  // 30 degrees about the camera z axis: R(1,0) = +sin, which column-major
  // order writes as Rot[1]; R(0,1) = -sin is Rot[3].
  const std::string text =
      "Frame\tTime\tB X\tY\tZ\tRoll\tPitch\tYaw\tResidual\tRot[0]\tRot[1]\tRot[2]\tRot[3]\tRot[4]\tRot[5]\tRot[6]\tRot[7]\tRot[8]\n"
      "1\t0.0\t10\t20\t30\t0\t0\t30\t0.5\t0.8660254037844386\t0.5\t0\t-0.5\t0.8660254037844386\t0\t0\t0\t1\n";
  const MocapCapture capture = cdcr::dataset::parse_qtm_6d_tsv(text);
  ASSERT_EQ(capture.body_names, std::vector<std::string>{"B"});
  ASSERT_EQ(capture.frames.size(), 1u);
  const Pose& pose = capture.frames[0].body_in_camera[0].value();
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_LE((pose.rotation - expected).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(pose.position_mm, Eigen::Vector3d(10, 20, 30));
  EXPECT_EQ(capture.frames[0].frame_number, 1);
  EXPECT_EQ(capture.frames[0].line, 2);
}

TEST(MocapImport, AcceptsQtmFiveDecimalsAndReorthonormalises) {
  const KnownCapture k = known_capture(30, 12);
  TsvStyle style;
  style.full_precision = false;
  const MocapImport result = cdcr::dataset::import_mocap(
      commanded_cables(30), cdcr::dataset::parse_qtm_6d_tsv(qtm_tsv({k.base, k.end}, style)),
      bodies("Base", "End platform"));
  for (std::size_t i = 0; i < 30; ++i) {
    const Eigen::Matrix3d& r = result.data.poses[i].rotation;
    EXPECT_LE((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-14);
    EXPECT_LE((r - k.end_in_base[i].rotation).cwiseAbs().maxCoeff(), 5e-5) << i;
    // 1e-5 of rotation error over ~1.5 m of lever arm.
    EXPECT_LE((result.data.poses[i].position_mm - k.end_in_base[i].position_mm).norm(), 0.2) << i;
  }
}

TEST(MocapImport, FindsBodiesAmongOthersAndExtraColumns) {
  const KnownCapture k = known_capture(5, 13);
  BodyTrack wand{"Wand", {}};
  std::mt19937_64 rng(1);
  for (int f = 0; f < 5; ++f) wand.in_camera.push_back(f == 2 ? OptionalPose{} : random_pose(rng, 900.0));
  TsvStyle style;
  style.timecode_column = true;
  style.crlf = true;
  const MocapCapture capture = cdcr::dataset::parse_qtm_6d_tsv(qtm_tsv({wand, k.end, k.base}, style));
  EXPECT_EQ(capture.body_names, (std::vector<std::string>{"Wand", "End platform", "Base"}));
  EXPECT_EQ(capture.column_header_line, 11);
  EXPECT_FALSE(capture.frames[2].body_in_camera[0].has_value());
  const MocapImport result =
      cdcr::dataset::import_mocap(commanded_cables(5), capture, bodies("Base", "End platform"));
  ASSERT_EQ(result.data.poses.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_LE((result.data.poses[i].position_mm - k.end_in_base[i].position_mm).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(MocapImport, NanEulerAnglesAloneDoNotMeanLost) {
  std::string text = qtm_tsv({known_capture(1, 2).base});
  // Replace Roll of frame 1 (the sixth field of the data row) by NaN.
  const std::size_t row = text.find("\n1\t") + 1;
  std::size_t at = row;
  for (int tab = 0; tab < 5; ++tab) at = text.find('\t', at) + 1;
  text.replace(at, text.find('\t', at) - at, "NaN");
  const MocapCapture capture = cdcr::dataset::parse_qtm_6d_tsv(text);
  EXPECT_TRUE(capture.frames[0].body_in_camera[0].has_value());
}

// ---------------------------------------------------------------------------
// Lost tracking.

KnownCapture capture_with_lost_frames(int frames, const std::vector<int>& base_lost, const std::vector<int>& end_lost) {
  KnownCapture k = known_capture(frames, 21);
  for (const int f : base_lost) k.base.in_camera[static_cast<std::size_t>(f)].reset();
  for (const int f : end_lost) k.end.in_camera[static_cast<std::size_t>(f)].reset();
  return k;
}

TEST(MocapImport, RejectsLostTrackingWithTheLine) {
  for (const LostStyle lost : {LostStyle::nan, LostStyle::zeros}) {
    const KnownCapture k = capture_with_lost_frames(6, {}, {3});
    TsvStyle style;
    style.lost = lost;
    const DatasetError e =
        import_rejection(commanded_cables(6), qtm_tsv({k.base, k.end}, style), bodies("Base", "End platform"));
    // 11 lines before the first frame; frame 4 is on line 15.
    EXPECT_EQ(e.line(), 15);
    EXPECT_STREQ(e.what(), "line 15: frame 4: body 'End platform' was not tracked");
  }
  const KnownCapture k = capture_with_lost_frames(6, {0}, {});
  const DatasetError e = import_rejection(commanded_cables(6), qtm_tsv({k.base, k.end}), bodies("Base", "End platform"));
  EXPECT_STREQ(e.what(), "line 12: frame 1: body 'Base' was not tracked");
  // Its own type, so that a caller can suggest skipping such frames.
  EXPECT_THROW(cdcr::dataset::import_mocap(commanded_cables(6), cdcr::dataset::parse_qtm_6d_tsv(qtm_tsv({k.base, k.end})),
                                           bodies("Base", "End platform")),
               cdcr::dataset::LostTrackingError);
}

TEST(MocapImport, SkipsLostFramesWithTheirCableRows) {
  const KnownCapture k = capture_with_lost_frames(8, {1, 6}, {1, 4});
  const Dataset commanded = commanded_cables(8);
  const MocapImport result = cdcr::dataset::import_mocap(
      commanded, cdcr::dataset::parse_qtm_6d_tsv(qtm_tsv({k.base, k.end})), bodies("Base", "End platform", LostFrames::skip));
  EXPECT_EQ(result.skipped_frames, (std::vector<long>{2, 5, 7}));
  const std::vector<int> kept = {0, 2, 3, 5, 7};
  ASSERT_EQ(result.data.sample_count(), 5);
  ASSERT_EQ(result.data.poses.size(), 5u);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    EXPECT_EQ(result.data.cables_mm.row(static_cast<Eigen::Index>(i)), commanded.cables_mm.row(kept[i]));
    EXPECT_LE((result.data.poses[i].position_mm - k.end_in_base[static_cast<std::size_t>(kept[i])].position_mm)
                  .cwiseAbs()
                  .maxCoeff(),
              1e-9);
  }
  const KnownCapture all_lost = capture_with_lost_frames(2, {0}, {1});
  EXPECT_STREQ(import_rejection(commanded_cables(2), qtm_tsv({all_lost.base, all_lost.end}),
                                bodies("Base", "End platform", LostFrames::skip))
                   .what(),
               "no frame has both bodies tracked");
}

// The payload each commanded row carried stays with its row.
TEST(MocapImport, KeepsThePayloadOfTheKeptRows) {
  const KnownCapture k = capture_with_lost_frames(6, {2}, {4});
  Dataset commanded = commanded_cables(6);
  commanded.has_payload = true;
  commanded.payload_kg.resize(6);
  commanded.payload_kg << 0.0, 0.1, 0.2, 0.3, 0.4, 0.5;
  const MocapImport result = cdcr::dataset::import_mocap(
      commanded, cdcr::dataset::parse_qtm_6d_tsv(qtm_tsv({k.base, k.end})), bodies("Base", "End platform", LostFrames::skip));
  ASSERT_TRUE(result.data.has_payload);
  ASSERT_EQ(result.data.payload_kg.size(), 4);
  EXPECT_EQ(result.data.payload_kg, Eigen::Vector4d(0.0, 0.1, 0.3, 0.5));
  const Dataset back = cdcr::dataset::parse_dataset_csv(cdcr::dataset::format_dataset_csv(result.data));
  EXPECT_EQ(back.payload_kg, result.data.payload_kg);

  const MocapImport without = cdcr::dataset::import_mocap(
      commanded_cables(6), cdcr::dataset::parse_qtm_6d_tsv(qtm_tsv({k.base, k.end})),
      bodies("Base", "End platform", LostFrames::skip));
  EXPECT_FALSE(without.data.has_payload);
}

// ---------------------------------------------------------------------------
// Refusals.

TEST(MocapImport, RejectsAMissingBody) {
  const KnownCapture k = known_capture(3, 3);
  const DatasetError e = import_rejection(commanded_cables(3), qtm_tsv({k.base, k.end}), bodies("Base", "Tip"));
  EXPECT_EQ(e.line(), 11);
  EXPECT_STREQ(e.what(), "line 11: end body 'Tip' is not in the capture (bodies: 'Base', 'End platform')");
}

TEST(MocapImport, RejectsACountMismatch) {
  const KnownCapture k = known_capture(4, 3);
  const DatasetError e = import_rejection(commanded_cables(5), qtm_tsv({k.base, k.end}), bodies("Base", "End platform"));
  EXPECT_EQ(e.line(), 0);
  EXPECT_STREQ(e.what(), "the capture has 4 frames but the commanded cable file has 5 rows; they are paired one to one");
}

TEST(MocapImport, RejectsPosesThatOverflow) {
  BodyTrack base{"Base", {Pose{Eigen::Matrix3d::Identity(), Eigen::Vector3d(1.5e308, 0, 0)}}};
  BodyTrack end{"End", {Pose{Eigen::Matrix3d::Identity(), Eigen::Vector3d(-1.5e308, 0, 0)}}};
  const DatasetError e = import_rejection(commanded_cables(1), qtm_tsv({base, end}), bodies("Base", "End"));
  EXPECT_EQ(e.line(), 12);
  EXPECT_STREQ(e.what(),
               "line 12: frame 1: the end-platform pose in the base frame overflows (coordinates out of range)");
  try {
    cdcr::dataset::import_mocap(commanded_cables(1), cdcr::dataset::parse_qtm_6d_tsv(qtm_tsv({base, end})),
                                bodies("Base", "End"));
  } catch (const cdcr::dataset::LostTrackingError&) {
    ADD_FAILURE() << "an overflow is not a tracking loss";
  } catch (const DatasetError&) {
  }
}

using BadTsv = cdcr::test_support::RejectionCase;

class MocapTsvRejects : public testing::TestWithParam<BadTsv> {};

TEST_P(MocapTsvRejects, WithOneLineNamingTheLine) {
  cdcr::test_support::expect_refusal_matches(tsv_rejection(GetParam().text), GetParam());
}

// A valid one-body, two-frame file, and ways to damage it.
const std::string kHeader =
    "NO_OF_FRAMES\t2\nNO_OF_BODIES\t1\nDATA_INCLUDED\t6D\nBODY_NAMES\tB\n"
    "Frame\tTime\tB X\tY\tZ\tRoll\tPitch\tYaw\tResidual\tRot[0]\tRot[1]\tRot[2]\tRot[3]\tRot[4]\tRot[5]\tRot[6]\tRot[7]\tRot[8]\t\n";
const std::string kRow1 = "1\t0.00000\t1.0\t2.0\t3.0\t0\t0\t0\t0.5\t1\t0\t0\t0\t1\t0\t0\t0\t1\t\n";
const std::string kRow2 = "2\t0.01000\t1.0\t2.0\t3.0\t0\t0\t0\t0.5\t1\t0\t0\t0\t1\t0\t0\t0\t1\t\n";

std::string with_row2(const std::string& row) { return kHeader + kRow1 + row; }

INSTANTIATE_TEST_SUITE_P(
    Damaged, MocapTsvRejects,
    testing::Values(
        BadTsv{"text_in_number", with_row2("2\t0.01\t1.0\tabc\t3.0\t0\t0\t0\t0.5\t1\t0\t0\t0\t1\t0\t0\t0\t1\n"), 7,
               "line 7: body 'B' Y: 'abc' is not a number"},
        BadTsv{"trailing_garbage", with_row2("2\t0.01\t1.0\t2.0\t3.0x\t0\t0\t0\t0.5\t1\t0\t0\t0\t1\t0\t0\t0\t1\n"), 7,
               "line 7: body 'B' Z: '3.0x' is not a number"},
        BadTsv{"missing_field", with_row2("2\t0.01\t1.0\t2.0\t3.0\t0\t0\t0\t0.5\t1\t0\t0\t0\t1\t0\t0\t0\n"), 7,
               "line 7: expected 18 tab-separated fields, found 17"},
        BadTsv{"empty_field", with_row2("2\t0.01\t1.0\t\t3.0\t0\t0\t0\t0.5\t1\t0\t0\t0\t1\t0\t0\t0\t1\n"), 7,
               "line 7: body 'B' Y: empty field"},
        BadTsv{"infinite", with_row2("2\t0.01\t1.0\t2.0\tinf\t0\t0\t0\t0.5\t1\t0\t0\t0\t1\t0\t0\t0\t1\n"), 7,
               "line 7: body 'B' Z: value is infinite"},
        BadTsv{"bad_frame_number", with_row2("two\t0.01\t1.0\t2.0\t3.0\t0\t0\t0\t0.5\t1\t0\t0\t0\t1\t0\t0\t0\t1\n"), 7,
               "line 7: Frame: 'two' is not a non-negative integer"},
        BadTsv{"not_orthonormal", with_row2("2\t0.01\t1.0\t2.0\t3.0\t0\t0\t0\t0.5\t1\t0\t0\t0\t1.01\t0\t0\t0\t1\n"), 7,
               "line 7: body 'B': Rot[0..8] is not a rotation matrix (max |R^T R - I| = 0.0201, det = 1.01)"},
        BadTsv{"reflection", with_row2("2\t0.01\t1.0\t2.0\t3.0\t0\t0\t0\t0.5\t1\t0\t0\t0\t1\t0\t0\t0\t-1\n"), 7,
               "line 7: body 'B': Rot[0..8] is not a rotation matrix (max |R^T R - I| = 0, det = -1)"},
        BadTsv{"truncated_export", kHeader + kRow1, 0,
               "NO_OF_FRAMES is 2 but the file holds 1 frames (truncated export?)"},
        BadTsv{"no_frames", kHeader, 5, "line 5: no frames after the column header row"},
        BadTsv{"body_count", "NO_OF_BODIES\t2\n" + kHeader.substr(kHeader.find("DATA")) + kRow1 + kRow2, 4,
               "line 4: NO_OF_BODIES is 2 but the columns hold 1 bodies"},
        BadTsv{"body_names", "BODY_NAMES\tA\n" + kHeader.substr(kHeader.find("Frame")) + kRow1, 1,
               "line 1: BODY_NAMES does not match the body columns of line 2"},
        BadTsv{"not_6d", "DATA_INCLUDED\t3D\n" + kHeader.substr(kHeader.find("Frame")) + kRow1, 1,
               "line 1: DATA_INCLUDED is '3D', expected 6D (a 6DOF export)"},
        BadTsv{"no_column_header", "NO_OF_FRAMES\t2\nMARKER_NAMES\ta\tb\n", 0,
               "no column header row (a line starting with 'Frame'): not a QTM 6DOF TSV export"},
        BadTsv{"no_bodies", "Frame\tTime\n1\t0.0\n", 1,
               "line 1: no rigid body columns ('<name> X', Y, Z, ...) in the column header row"},
        BadTsv{"incomplete_block", "Frame\tTime\tB X\tY\tZ\tRoll\tPitch\tYaw\tResidual\tRot[0]\n", 1,
               "line 1: column 3: body 'B' must have the 16 columns X, Y, Z, three angles, Residual, Rot[0], ..., "
               "Rot[8]"},
        BadTsv{"bad_frame_count", "NO_OF_FRAMES\tmany\n" + kHeader.substr(kHeader.find("Frame")) + kRow1, 1,
               "line 1: NO_OF_FRAMES: 'many' is not a non-negative integer"}),
    cdcr::test_support::rejection_case_name);

TEST(MocapImport, ReadErrorsNameThePath) {
  const std::string path = testing::TempDir() + "cdcr_mocap_missing.tsv";
  try {
    cdcr::dataset::read_qtm_6d_tsv(path);
    FAIL();
  } catch (const DatasetError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": cannot open file");
  }
}

// ---------------------------------------------------------------------------
// The command.

struct Files {
  std::string cables;
  std::string mocap;
  std::string out;
};

Files write_inputs(const std::string& tag, const Dataset& commanded, const std::string& tsv) {
  const std::string dir = testing::TempDir() + "cdcr_import_" + tag + "_" + std::to_string(getpid());
  Files files{dir + "_cables.csv", dir + "_capture.tsv", dir + "_data.csv"};
  cdcr::dataset::write_dataset_csv(files.cables, commanded);
  std::ofstream(files.mocap, std::ios::binary) << tsv;
  std::remove(files.out.c_str());
  return files;
}

cdcr::cli::ImportMocapOptions command_options(const Files& files, bool skip_lost = false) {
  cdcr::cli::ImportMocapOptions o;
  o.cables_path = files.cables;
  o.mocap_path = files.mocap;
  o.base_body = "Base";
  o.end_body = "End platform";
  o.out_path = files.out;
  o.skip_lost = skip_lost;
  return o;
}

TEST(ImportMocapCommand, WritesTheDataset) {
  const KnownCapture k = known_capture(12, 31);
  const Dataset commanded = commanded_cables(12, 3);
  const Files files = write_inputs("ok", commanded, qtm_tsv({k.base, k.end}));
  const cdcr::cli::CommandOutput output = cdcr::cli::run_import_mocap(command_options(files));
  EXPECT_EQ(output.text, "wrote 12 samples (3 segments) to " + files.out + "\n");
  const Dataset written = cdcr::dataset::read_dataset_csv(files.out, cdcr::dataset::PoseColumns::required);
  EXPECT_EQ(written.cables_mm, commanded.cables_mm);
  for (std::size_t i = 0; i < 12; ++i) {
    EXPECT_LE((written.poses[i].rotation - k.end_in_base[i].rotation).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_LE((written.poses[i].position_mm - k.end_in_base[i].position_mm).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(ImportMocapCommand, ReportsSkippedFrames) {
  const KnownCapture k = capture_with_lost_frames(6, {2}, {5});
  const Files files = write_inputs("skip", commanded_cables(6), qtm_tsv({k.base, k.end}));
  const cdcr::cli::CommandOutput output = cdcr::cli::run_import_mocap(command_options(files, true));
  EXPECT_EQ(output.text, "wrote 4 samples (2 segments) to " + files.out +
                             "\nskipped 2 frames where a body was not tracked: 3, 6\n");
  EXPECT_EQ(cdcr::dataset::read_dataset_csv(files.out).sample_count(), 4);
}

TEST(ImportMocapCommand, RefusalsAreInputErrorsNamingTheFile) {
  const KnownCapture k = capture_with_lost_frames(6, {2}, {});
  const Files files = write_inputs("lost", commanded_cables(6), qtm_tsv({k.base, k.end}));
  try {
    cdcr::cli::run_import_mocap(command_options(files));
    FAIL();
  } catch (const cdcr::cli::InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              files.mocap + ": line 14: frame 3: body 'Base' was not tracked (--skip-lost drops such frames)");
  }
  std::ifstream out(files.out);
  EXPECT_FALSE(out.good()) << "nothing is written on failure";

  cdcr::cli::ImportMocapOptions same = command_options(files);
  same.end_body = "Base";
  EXPECT_THROW(cdcr::cli::run_import_mocap(same), cdcr::cli::UsageError);

  cdcr::cli::ImportMocapOptions missing = command_options(files);
  missing.end_body = "Tip";
  try {
    cdcr::cli::run_import_mocap(missing);
    FAIL();
  } catch (const cdcr::cli::InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              files.mocap + ": line 11: end body 'Tip' is not in the capture (bodies: 'Base', 'End platform')");
  }
}

using cdcr::test_support::CliRun;
using cdcr::test_support::run_cdcr;

TEST(ImportMocapCommand, ThroughTheExecutable) {
  const KnownCapture k = capture_with_lost_frames(4, {}, {1});
  const Files files = write_inputs("cli", commanded_cables(4), qtm_tsv({k.base, k.end}));
  const std::string arguments = "import-mocap --cables '" + files.cables + "' --mocap '" + files.mocap +
                                "' --base-body Base --end-body 'End platform' --out '" + files.out + "'";

  const CliRun lost = run_cdcr(arguments);
  EXPECT_EQ(lost.exit_code, 1);
  EXPECT_EQ(lost.out, "");
  EXPECT_EQ(lost.err, "cdcr: error: " + files.mocap +
                          ": line 13: frame 2: body 'End platform' was not tracked (--skip-lost drops such frames)\n");

  const CliRun skipped = run_cdcr(arguments + " --skip-lost");
  EXPECT_EQ(skipped.exit_code, 0) << skipped.err;
  EXPECT_EQ(skipped.out, "wrote 3 samples (2 segments) to " + files.out +
                             "\nskipped 1 frame where a body was not tracked: 2\n");
  EXPECT_EQ(skipped.err, "");

  const CliRun usage = run_cdcr("import-mocap --cables x.csv --mocap y.tsv --base-body A --end-body B");
  EXPECT_EQ(usage.exit_code, 2);
  EXPECT_EQ(usage.err.rfind("cdcr: usage: --out is required", 0), 0u) << usage.err;
}

// ---------------------------------------------------------------------------
// Motion sequences: the commanded file's t_s goes into the dataset.

Dataset commanded_sequence(int rows) {
  Dataset data = commanded_cables(rows);
  data.has_time = true;
  data.time_s.resize(rows);
  // A pause of a minute before row 3 starts a second session.
  for (int r = 0; r < rows; ++r) data.time_s[r] = 1.5 * (r + 1) + (r >= 3 ? 60.0 : 0.0);
  data.session_starts = cdcr::dataset::session_starts_from_times(data.time_s);
  return data;
}

TEST(MocapImport, KeepsTheTimeOfAMotionSequence) {
  const KnownCapture k = known_capture(6, 5);
  const Dataset commanded = commanded_sequence(6);
  ASSERT_EQ(commanded.session_starts, (std::vector<int>{0, 3}));
  const MocapImport result = cdcr::dataset::import_mocap(
      commanded, cdcr::dataset::parse_qtm_6d_tsv(qtm_tsv({k.base, k.end})), bodies("Base", "End platform"));
  ASSERT_TRUE(result.data.has_time);
  EXPECT_EQ(result.data.time_s, commanded.time_s);
  EXPECT_EQ(result.data.session_starts, commanded.session_starts);

  // Without a time column the rows stay independent samples.
  const MocapImport samples = cdcr::dataset::import_mocap(
      commanded_cables(6), cdcr::dataset::parse_qtm_6d_tsv(qtm_tsv({k.base, k.end})), bodies("Base", "End platform"));
  EXPECT_FALSE(samples.data.has_time);
  EXPECT_EQ(samples.data.time_s.size(), 0);
}

// The robot moved through a row whose frame was lost: dropping it would
// leave a path the robot did not take.
TEST(MocapImport, RefusesToDropARowOfAMotionSequence) {
  const KnownCapture k = capture_with_lost_frames(6, {}, {3});
  for (const LostFrames lost : {LostFrames::reject, LostFrames::skip}) {
    const DatasetError e =
        import_rejection(commanded_sequence(6), qtm_tsv({k.base, k.end}), bodies("Base", "End platform", lost));
    EXPECT_STREQ(e.what(),
                 "line 15: frame 4: body 'End platform' was not tracked, and a row of a motion sequence (t_s) cannot "
                 "be dropped");
  }
}

TEST(ImportMocapCommand, WritesTheTimeColumnBack) {
  const KnownCapture k = known_capture(6, 9);
  const Dataset commanded = commanded_sequence(6);
  const Files files = write_inputs("time", commanded, qtm_tsv({k.base, k.end}));
  cdcr::cli::run_import_mocap(command_options(files));
  std::ifstream file(files.out);
  std::string line;
  while (std::getline(file, line) && line.rfind('#', 0) == 0) {
  }
  EXPECT_EQ(line.rfind("t_s,l1_1,", 0), 0u) << line;
  const Dataset written = cdcr::dataset::read_dataset_csv(files.out, cdcr::dataset::PoseColumns::required);
  ASSERT_TRUE(written.has_time);
  EXPECT_EQ(written.time_s, commanded.time_s);
  EXPECT_EQ(written.session_starts, (std::vector<int>{0, 3}));
  EXPECT_EQ(written.cables_mm, commanded.cables_mm);
}

}  // namespace
