// Writes the seed corpus of the fuzzers into <dir>/image, <dir>/csv and
// <dir>/tsv: small valid files, produced by the project's own writers where
// there is one.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "dataset/csv_dataset.hpp"
#include "export/image_writer.hpp"
#include "trained_model/trained_model.hpp"

#include "../support/synthetic_trained_model.hpp"
#include "../support/v1_image.hpp"

namespace {

using cdcr::training::TrainedModel;

TrainedModel small_model(int segments, int points, cdcr::model::InputEncoding encoding) {
  TrainedModel m;
  m.encoding = encoding;
  m.geometry = cdcr::model::RobotGeometry<double>::uniform(segments, 120.0, 67.0);
  const int d = 2 * segments;
  m.input_mean = Eigen::VectorXd::Constant(d, 0.01);
  m.input_scale = Eigen::VectorXd::Constant(d, 0.2);
  m.length_scales = Eigen::VectorXd::LinSpaced(d, 0.5, 1.5);
  m.inputs.resize(points, d);
  m.alpha.resize(points, 6);
  for (int i = 0; i < points; ++i) {
    for (int k = 0; k < d; ++k) m.inputs(i, k) = 0.05 * std::sin(1.0 + i + 3.0 * k);
    for (int k = 0; k < 6; ++k) m.alpha(i, k) = 0.1 * std::cos(2.0 * i + k);
  }
  m.output_mean << 0.5, -0.2, 1.0, 0.001, -0.002, 0.0;
  m.dataset_hash = 0x0123456789abcdefull;
  m.created_unix_s = 1583020800;
  m.validation_samples = 50;
  m.trainer = "cdcr fuzz seed";
  return m;
}

void write(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

void write(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes) {
  write(path, std::string(bytes.begin(), bytes.end()));
}

cdcr::dataset::Dataset small_dataset(int segments, int rows, bool poses, bool payload = false) {
  cdcr::dataset::Dataset data;
  data.segment_count = segments;
  data.has_poses = poses;
  data.has_payload = payload;
  data.cables_mm.resize(rows, 4 * segments);
  if (payload) data.payload_kg.resize(rows);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < 4 * segments; ++c) data.cables_mm(r, c) = 120.0 + 0.37 * (r + 1) * (c - 1.5);
    if (payload) data.payload_kg[r] = 0.25 * r;
    if (poses) {
      cdcr::model::Pose<double> pose;
      pose.rotation = Eigen::AngleAxisd(0.1 * (r + 1), Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
      pose.position_mm = Eigen::Vector3d(3.0 * r, -2.0, 230.0 + r);
      data.poses.push_back(pose);
    }
  }
  return data;
}

std::string tsv_body(double x, double y, double z, const Eigen::Matrix3d& r) {
  char text[512];
  std::snprintf(text, sizeof text, "%.5f\t%.5f\t%.5f\t0.00000\t0.00000\t0.00000\t0.71000", x, y, z);
  std::string out = text;
  for (int k = 0; k < 9; ++k) {
    std::snprintf(text, sizeof text, "\t%.5f", r(k % 3, k / 3));
    out += text;
  }
  return out;
}

std::string qtm_export() {
  std::string text =
      "NO_OF_FRAMES\t3\nNO_OF_CAMERAS\t8\nNO_OF_BODIES\t2\nFREQUENCY\t100\nNO_OF_ANALOG\t0\nANALOG_FREQUENCY\t0\n"
      "DESCRIPTION\t--\nTIME_STAMP\t2020-03-01, 10:00:00\t1234.56789\nDATA_INCLUDED\t6D\nBODY_NAMES\tbase\tend\n"
      "Frame\tTime\tbase X\tY\tZ\tRoll\tPitch\tYaw\tResidual\tRot[0]\tRot[1]\tRot[2]\tRot[3]\tRot[4]\tRot[5]\tRot[6]"
      "\tRot[7]\tRot[8]\tend X\tY\tZ\tRoll\tPitch\tYaw\tResidual\tRot[0]\tRot[1]\tRot[2]\tRot[3]\tRot[4]\tRot[5]"
      "\tRot[6]\tRot[7]\tRot[8]\t\n";
  const std::string lost = "NaN\tNaN\tNaN\tNaN\tNaN\tNaN\tNaN\tNaN\tNaN\tNaN\tNaN\tNaN\tNaN\tNaN\tNaN\tNaN";
  for (int f = 0; f < 3; ++f) {
    const Eigen::Matrix3d base = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Matrix3d end = Eigen::AngleAxisd(0.2 * f, Eigen::Vector3d::UnitX()).toRotationMatrix() * base;
    char time[32];
    std::snprintf(time, sizeof time, "%.5f", 0.01 * f);
    text += std::to_string(f + 1) + "\t" + time + "\t" + tsv_body(1000.0, -250.0, 12.5, base) + "\t" +
            (f == 1 ? lost : tsv_body(1010.0 + f, -240.0, 480.0, end)) + "\t\n";
  }
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_fuzz_seeds <dir>\n");
    return 2;
  }
  namespace fs = std::filesystem;
  const fs::path root = argv[1];
  for (const char* kind : {"image", "csv", "tsv"}) fs::create_directories(root / kind);

  using cdcr::model::InputEncoding;
  write(root / "image" / "one_segment.bin",
        cdcr::exporting::write_image(small_model(1, 3, InputEncoding::bend_vector)));
  write(root / "image" / "two_segments_joint_angles.bin",
        cdcr::exporting::write_image(small_model(2, 4, InputEncoding::joint_angles)));
  TrainedModel sparse = small_model(2, 3, InputEncoding::bend_vector);
  sparse.kind = cdcr::model::ImageModelKind::sparse_gp;
  sparse.fitted_rows = 40;
  write(root / "image" / "two_segments_sparse.bin", cdcr::exporting::write_image(sparse));
  // Format v1, which boards in the field still carry.
  {
    // v2.2: a hysteresis block (two play operators per cable).
    TrainedModel with_hysteresis = small_model(1, 3, InputEncoding::bend_vector);
    std::mt19937 rng(7);
    with_hysteresis.hysteresis = cdcr::test_support::synthetic_hysteresis(with_hysteresis.geometry, 2, rng);
    write(root / "image" / "one_segment_hysteresis.bin", cdcr::exporting::write_image(with_hysteresis));
  }
  write(root / "image" / "one_segment_v1.bin",
        cdcr::test_support::v1_image(small_model(1, 3, InputEncoding::bend_vector)));

  write(root / "csv" / "cables.csv", cdcr::dataset::format_dataset_csv(small_dataset(2, 3, false)));
  write(root / "csv" / "poses.csv", cdcr::dataset::format_dataset_csv(small_dataset(1, 2, true), "measured"));
  write(root / "csv" / "payload_poses.csv",
        cdcr::dataset::format_dataset_csv(small_dataset(2, 3, true, true), "measured with a payload"));
  write(root / "csv" / "payload_cables.csv", cdcr::dataset::format_dataset_csv(small_dataset(1, 2, false, true)));
  // A motion sequence of two sessions (a pause of more than 30 s between them).
  cdcr::dataset::Dataset sequence = small_dataset(2, 4, true);
  sequence.has_time = true;
  sequence.time_s.resize(4);
  sequence.time_s << 0.75, 1.5, 40.0, 41.25;
  sequence.session_starts = cdcr::dataset::session_starts_from_times(sequence.time_s);
  write(root / "csv" / "time_sequence.csv", cdcr::dataset::format_dataset_csv(sequence, "a motion sequence"));
  // A segment of three cables before one of four.
  cdcr::dataset::Dataset three_then_four = small_dataset(2, 3, true);
  three_then_four.segment_cables = {3, 4};
  three_then_four.cables_mm = three_then_four.cables_mm.leftCols(7).eval();
  write(root / "csv" / "three_then_four_cables.csv",
        cdcr::dataset::format_dataset_csv(three_then_four, "three cables, then four"));
  write(root / "csv" / "crlf_bom_comments.csv",
        std::string("\xEF\xBB\xBF# exported\r\n\r\nl1_1,l1_2,l1_3,l1_4,x,y,z,qw,qx,qy,qz\r\n"
                    "120,+121.5,119, 118 ,1e1,-0,240,1,0,0,0\r\n# end\r\n"));

  write(root / "tsv" / "two_bodies.tsv", qtm_export());
  // Finite coordinates whose difference overflows a double.
  const std::string identity = "\t0.5\t1\t0\t0\t0\t1\t0\t0\t0\t1";
  const std::string block_titles =
      " X\tY\tZ\tRoll\tPitch\tYaw\tResidual\tRot[0]\tRot[1]\tRot[2]\tRot[3]\tRot[4]\tRot[5]\tRot[6]\tRot[7]\tRot[8]";
  write(root / "tsv" / "huge_coordinates.tsv",
        "Frame\tTime\ta" + block_titles + "\tb" + block_titles + "\n" +
            "1\t0\t1.5e308\t0\t0\t0\t0\t0" + identity + "\t-1.5e308\t0\t0\t0\t0\t0" + identity + "\n");
  return 0;
}
