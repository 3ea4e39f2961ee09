// cdcr-runtime --replay: the forward path over recorded cable lengths. With
// an image that models the cables' hysteresis the rows are a motion sequence
// (the data's t_s column): the state is carried from row to row, each
// session starting at home, and the pose is that of the effective lengths.

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <cdcr/firmware/protocol/frames.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/model/hysteresis_sequence.hpp>
#include <cdcr/model/unit_quaternion.hpp>

#include "cli/cli_errors.hpp"
#include "dataset/csv_dataset.hpp"
#include "export/binary_file.hpp"
#include "runtime_modes.hpp"
#include "sim/simulated_platform.hpp"
#include "view/view_session.hpp"

namespace cdcr::runtime_host {

namespace fw = cdcr::firmware;
namespace model = cdcr::model;
namespace protocol = cdcr::firmware::protocol;
namespace sim = cdcr::sim;
using cli::InputError;

void require_rate(double rate_hz) {
  if (!(rate_hz > 0) || !(rate_hz <= 100000)) throw std::invalid_argument("--rate must be in (0, 100000] Hz");
}

namespace {

// The rows as the drives would have sent them, through a view into an MCAP
// recording: each row's CABLE_FEEDBACK frames at its time (a row every
// millisecond without a t_s column), HOMING at each session's start when the
// image tracks the hysteresis. Rows a frame cannot carry are left out, and
// counted.
void record_rows(const std::string& image_path, const cdcr::dataset::Dataset& data, const fw::Runtime& runtime,
                 const ViewChoice& choice) {
  view::ViewOptions options;
  options.scene_rate_hz = choice.scene_rate_hz;
  view::ViewSession session(cdcr::exporting::read_binary_file(image_path), options,
                            view::ViewOutputs{-1, choice.record_path, ""});
  view::RobotView& robot_view = session.view();
  const fw::Geometry& geometry = runtime.geometry();
  std::size_t next_session = 0;
  long left_out = 0;
  for (Eigen::Index i = 0; i < data.cables_mm.rows(); ++i) {
    const auto time_ns = static_cast<std::uint64_t>(
        data.has_time ? std::llround(data.time_s[i] * 1e9) : std::int64_t(i) * 1000000);
    cdcr::hal::CanFrame frame;
    if (next_session < data.session_starts.size() && data.session_starts[next_session] == i) {
      ++next_session;
      if (runtime.hysteresis().active()) {
        protocol::encode(protocol::Homing{true}, frame);
        robot_view.on_frame(frame, time_ns);
      }
    }
    std::vector<cdcr::hal::CanFrame> frames;
    const Eigen::VectorXd row = data.cables_mm.row(i).transpose();
    for (int s = 0; s < geometry.segment_count; ++s) {
      const auto feedback = protocol::segment_cables_frame<protocol::CableFeedback>(
          s, row, geometry.first_cable(s), geometry.segments[s].cables.count);
      if (!protocol::encode(feedback, frame)) break;
      frames.push_back(frame);
    }
    if (int(frames.size()) != geometry.segment_count) {
      ++left_out;
      continue;
    }
    for (const cdcr::hal::CanFrame& f : frames) robot_view.on_frame(f, time_ns);
  }
  session.close_recording();
  std::printf("recording: %s, %llu messages of %lld rows (%ld left out: lengths a CABLE_FEEDBACK frame cannot "
              "carry)\n",
              choice.record_path.c_str(), static_cast<unsigned long long>(session.recorded_messages()),
              static_cast<long long>(data.cables_mm.rows()), left_out);
}

}  // namespace

int replay(const std::string& image_path, const std::string& cables_path, const std::string& out_path,
           const ViewChoice& view) {
  sim::SimulatedPlatform platform;
  platform.storage.assign(cdcr::exporting::read_binary_file(image_path));
  fw::Runtime runtime(platform.hal, fw::Geometry::prototype());
  if (runtime.init() != fw::RuntimeState::run) {
    std::string message = std::string("image ") + image_path + ": " + fw::to_string(runtime.boot_fault());
    if (runtime.boot_fault() == fw::FaultCode::image_invalid) {
      message += std::string(" (") + model::to_string(runtime.boot_fault_detail().image_status()) + ")";
    }
    throw InputError(message);
  }
  cdcr::dataset::Dataset data;
  try {
    data = cdcr::dataset::read_dataset_csv(cables_path);
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  if (data.segment_count != runtime.geometry().segment_count) {
    throw InputError(cables_path + ": " + std::to_string(data.segment_count) + " segments, the image has " +
                     std::to_string(runtime.geometry().segment_count));
  }
  if (data.cable_count() != runtime.geometry().cable_count()) {
    throw InputError(cables_path + ": " + std::to_string(data.cable_count()) + " cables, the image's robot has " +
                     std::to_string(runtime.geometry().cable_count()));
  }
  // A payload model takes each row's payload as if it had come in a PAYLOAD
  // frame with the row's cables; a model without the input ignores the column.
  const bool payload_input = runtime.correction().has_payload_input();
  if (payload_input && !data.has_payload) {
    throw InputError(cables_path + ": the image takes a payload input and the data have no payload_kg column");
  }
  if (!payload_input && data.has_payload) {
    std::fprintf(stderr, "note: %s: the payload_kg column is ignored: the image has no payload input\n",
                 cables_path.c_str());
  }
  const fw::HysteresisTracker& hysteresis = runtime.hysteresis();
  if (hysteresis.active() && !data.has_time) {
    throw InputError(cables_path + ": the image compensates the cables' hysteresis and needs a motion sequence (a t_s "
                                   "column), but the rows have no time");
  }
  Eigen::MatrixXf effective_mm(data.cables_mm.rows(), data.cables_mm.cols());
  Eigen::MatrixXf history(data.cables_mm.rows(), data.cables_mm.cols());
  if (hysteresis.active()) {
    const model::Status s = model::effective_lengths_over_sequence(
        hysteresis.hysteresis_model(), runtime.geometry(), data.cables_mm, data.session_starts.data(),
        static_cast<int>(data.session_starts.size()), effective_mm, model::SessionStart::homed,
        runtime.correction().takes_history() ? &history : nullptr);
    if (s != model::Status::ok) throw InputError(cables_path + ": hysteresis: " + model::to_string(s));
  }
  std::FILE* out = std::fopen(out_path.c_str(), "w");
  if (out == nullptr) throw InputError("cannot write " + out_path);
  std::fprintf(out, "x,y,z,qw,qx,qy,qz,r95_mm,r95_deg,extrapolating\n");
  for (Eigen::Index i = 0; i < data.cables_mm.rows(); ++i) {
    const fw::Cables cables = hysteresis.active() ? fw::Cables(effective_mm.row(i).transpose())
                                                  : fw::Cables(data.cables_mm.row(i).transpose().cast<float>());
    if (payload_input && !runtime.set_payload_kg(static_cast<float>(data.payload_kg[i]))) {
      std::fclose(out);
      throw InputError(cables_path + ": sample " + std::to_string(i + 1) + ": payload " +
                       std::to_string(data.payload_kg[i]) + " kg is beyond what the PAYLOAD frame carries");
    }
    if (runtime.correction().takes_history()) {
      const fw::Cables row_history = history.row(i).transpose();
      runtime.set_history_inputs(row_history.data());
    }
    fw::PoseEstimate estimate;
    if (const model::Status s = runtime.estimate_pose(cables, estimate); s != model::Status::ok) {
      std::fclose(out);
      throw InputError(cables_path + ": sample " + std::to_string(i + 1) + ": " + model::to_string(s));
    }
    const model::Pose<double> pose = estimate.pose.cast<double>();
    const Eigen::Quaterniond q = model::canonical_quaternion(pose.rotation);
    const model::PoseUncertainty<fw::Scalar> uncertainty = runtime.estimate_uncertainty(estimate);
    std::fprintf(out, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d\n", pose.position_mm.x(), pose.position_mm.y(),
                 pose.position_mm.z(), q.w(), q.x(), q.y(), q.z(), static_cast<double>(uncertainty.r95_mm),
                 static_cast<double>(uncertainty.r95_deg), uncertainty.extrapolating ? 1 : 0);
  }
  if (std::fclose(out) != 0) throw InputError("cannot write " + out_path);
  if (!view.record_path.empty()) record_rows(image_path, data, runtime, view);
  return 0;
}

}  // namespace cdcr::runtime_host
