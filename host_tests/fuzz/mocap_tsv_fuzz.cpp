// Fuzzes the QTM 6DOF TSV reader and the eq. (21) import
// (tools/dataset/mocap_import.cpp). An accepted capture must hold finite
// rotations and positions for every tracked body, and importing it must give
// finite poses in the base frame or a one-line DatasetError.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "dataset/mocap_import.hpp"
#include "fuzz_checks.hpp"

namespace {

using cdcr::fuzz::check_rejection;
using cdcr::fuzz::require;
using namespace cdcr::dataset;

void check_rotation(const Eigen::Matrix3d& r) {
  require(r.allFinite());
  require((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-12);
  require(r.determinant() > 0);
}

void check_capture(const MocapCapture& capture) {
  require(!capture.body_names.empty() && !capture.frames.empty());
  for (const MocapFrame& frame : capture.frames) {
    require(frame.line > capture.column_header_line);
    require(frame.body_in_camera.size() == capture.body_names.size());
    for (const auto& pose : frame.body_in_camera) {
      if (!pose) continue;
      check_rotation(pose->rotation);
      require(pose->position_mm.allFinite());
    }
  }
}

void check_import(const MocapCapture& capture) {
  Dataset commanded;
  commanded.segment_count = 1;
  commanded.cables_mm = Eigen::MatrixXd::Constant(static_cast<Eigen::Index>(capture.frames.size()), 4, 120.0);
  MocapImportOptions options;
  options.base_body = capture.body_names.front();
  options.end_body = capture.body_names.back();
  options.lost_frames = LostFrames::skip;
  try {
    const MocapImport result = import_mocap(commanded, capture, options);
    require(result.data.sample_count() + result.skipped_frames.size() == capture.frames.size());
    require(result.data.poses.size() == static_cast<std::size_t>(result.data.sample_count()));
    for (const auto& pose : result.data.poses) {
      check_rotation(pose.rotation);
      require(pose.position_mm.allFinite());
    }
    const Dataset back = parse_dataset_csv(format_dataset_csv(result.data), PoseColumns::required);
    require(back.sample_count() == result.data.sample_count());
  } catch (const DatasetError& e) {
    check_rejection(e);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const MocapCapture capture = parse_qtm_6d_tsv(text);
    check_capture(capture);
    check_import(capture);
  } catch (const DatasetError& e) {
    check_rejection(e);
  }
  return 0;
}
