// The host side of the SocketCAN test: builds the model image and the frames
// the bus test sends, and checks what the runtime put on the bus (a candump -L
// log) against the model library.
//
//   socketcan_check image <out.img>
//   socketcan_check frames <image>            shell assignments for the driver
//   socketcan_check check <image> <candump log>
//   socketcan_check fd-values <image>         the FD test's physical values (fd_client.py)
//   socketcan_check fd-check <image> <summary>  fd_client.py's poses and setpoints
//   socketcan_check pose-targets <image>      six reachable pose targets, physical values
//                                             (host_tests/canopen/uml_host_peer.py)
//
// The log is cut into phases by marker frames (id 0x7F0, one byte: the phase
// number) that the driver sends between the steps of the test.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <cdcr/firmware/fault.hpp>
#include <cdcr/firmware/protocol.hpp>
#include <cdcr/model/compensated_kinematics.hpp>
#include <cdcr/model/flash_image.hpp>
#include <cdcr/model/gp_correction.hpp>

#include "export/image_writer.hpp"
#include "synthetic_trained_model.hpp"

namespace {

namespace model = cdcr::model;
namespace protocol = cdcr::firmware::protocol;
using cdcr::firmware::FaultCode;
using cdcr::firmware::RuntimeState;
using cdcr::hal::CanFrame;

constexpr std::uint32_t kMarkerId = 0x7F0;
constexpr int kSegments = 4;
constexpr std::uint8_t kTargetSequence = 5;
// Quantisation of the pose frames (0.01 mm, Q15) plus the float arithmetic of
// the runtime against this double reference.
constexpr double kPoseToleranceMm = 0.02;
constexpr double kOrientationToleranceRad = 5e-4;
// Setpoints are quantised to 0.01 mm per cable; through the lever of the
// whole robot that moves the tip by a few hundredths of a millimetre.
constexpr double kSetpointReachToleranceMm = 0.3;

struct Model {
  std::vector<std::uint8_t> bytes;
  model::ImageView image;
  model::RobotGeometry<double> geometry;
  model::GpCorrection<double, double> correction;
};

bool load_model(const std::string& path, Model& m) {
  std::ifstream in(path, std::ios::binary);
  m.bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (model::parse_image(m.bytes.data(), m.bytes.size(), m.image) != model::ImageStatus::ok) return false;
  return model::geometry_from_image(m.image, m.geometry) == model::Status::ok &&
         m.correction.bind(m.image) == model::Status::ok;
}

// The cable set the feeders send: a gently bent robot, quantised as on the bus.
model::CableVector<double> bent_cables(const Model& m, double theta_rad, double alpha_offset_rad) {
  model::JointVector<double> joints(2 * m.geometry.segment_count);
  for (int s = 0; s < m.geometry.segment_count; ++s) {
    joints[2 * s] = alpha_offset_rad + 0.7 * (s + 1);
    joints[2 * s + 1] = theta_rad;
  }
  model::CableVector<double> cables;
  model::cables_from_joints(joints, m.geometry, cables);
  for (int i = 0; i < cables.size(); ++i) cables[i] = protocol::cable_length_as_transmitted(cables[i]);
  return cables;
}

model::CableVector<double> feedback_cables(const Model& m) { return bent_cables(m, 0.15, 0.0); }

// Pose targets: the compensated model's own poses at these bends (reachable
// by construction). Phase 8 sends the first kPoseTargets, each up to
// kPoseTargetAttempts times (a target refused in FAULT is sent again, as a
// planner would), every attempt with a sequence number of its own; the
// CiA 402 test takes all six (pose-targets).
constexpr double kPoseTargetBends[][2] = {{0.1, 0.0}, {0.25, 1.0}, {0.05, -2.0}, {0.3, 2.5}, {0.2, -0.8}, {0.15, 1.8}};
constexpr int kPoseTargets = 4;
constexpr int kPoseTargetAttempts = 4;
std::uint8_t pose_target_sequence(int target, int attempt) {
  return std::uint8_t(0x20 + kPoseTargetAttempts * target + attempt);
}
model::Pose<double> pose_target(const Model& m, int target) {
  model::ForwardResult<double> result;
  model::compensated_forward(bent_cables(m, kPoseTargetBends[target][0], kPoseTargetBends[target][1]), m.geometry,
                             m.correction, result);
  return result.compensated;
}

model::Vec3<double> target_position_mm(const Model& m) {
  model::ForwardResult<double> result;
  model::compensated_forward(bent_cables(m, 0.25, 0.4), m.geometry, m.correction, result);
  return result.compensated.position_mm;
}

std::string hex(const CanFrame& frame) {
  std::string text;
  char byte[3];
  for (int i = 0; i < frame.dlc; ++i) {
    std::snprintf(byte, sizeof(byte), "%02X", frame.data[i]);
    text += byte;
  }
  return text;
}

// Another training set size or seed gives another model for the same robot
// (the deploy test sends those).
int write_image(const std::string& path, int training_points = 24, std::uint32_t seed = 20200921) {
  cdcr::test_support::SyntheticModelOptions options;
  options.segments = kSegments;
  options.training_points = training_points;
  options.seed = seed;
  cdcr::training::TrainedModel trained = cdcr::test_support::synthetic_trained_model(options);
  trained.geometry = model::RobotGeometry<double>::prototype();
  // Corrections of a few tenths of a millimetre, as a trained model makes.
  for (int k = 0; k < 6; ++k) {
    trained.output_mean[k] *= k < 3 ? 0.1 : 0.001;
    trained.output_scale[k] *= k < 3 ? 0.1 : 0.001;
  }
  const std::vector<std::uint8_t> bytes = cdcr::exporting::write_image(trained);
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  return out ? 0 : 1;
}

int print_frames(const Model& m) {
  const model::CableVector<double> cables = feedback_cables(m);
  for (int s = 0; s < m.geometry.segment_count; ++s) {
    const protocol::CableFeedback feedback{s, {cables[4 * s], cables[4 * s + 1], cables[4 * s + 2], cables[4 * s + 3]}};
    CanFrame frame;
    protocol::encode(feedback, frame);
    std::printf("FEEDBACK_%d=%s\n", s, hex(frame).c_str());
  }
  std::printf("SEGMENTS=%d\n", m.geometry.segment_count);
  const model::Vec3<double> target = target_position_mm(m);
  CanFrame xy, z;
  protocol::encode(protocol::TargetPositionXy{target.x(), target.y()}, xy);
  protocol::encode(protocol::TargetPositionZ{target.z(), protocol::TargetMode::position, false, kTargetSequence}, z);
  std::printf("TARGET_XY=%s\nTARGET_Z=%s\n", hex(xy).c_str(), hex(z).c_str());
  std::printf("POSE_TARGETS=%d\nPOSE_TARGET_ATTEMPTS=%d\n", kPoseTargets, kPoseTargetAttempts);
  for (int t = 0; t < kPoseTargets; ++t) {
    const model::Pose<double> pose = pose_target(m, t);
    const Eigen::Quaterniond q(pose.rotation);
    CanFrame orientation, position;
    protocol::encode(protocol::TargetOrientation{q.w(), q.x(), q.y(), q.z()}, orientation);
    protocol::encode(protocol::TargetPositionXy{pose.position_mm.x(), pose.position_mm.y()}, position);
    std::printf("POSE_TARGET_Q_%d=%s\nPOSE_TARGET_XY_%d=%s\n", t, hex(orientation).c_str(), t, hex(position).c_str());
    for (int a = 0; a < kPoseTargetAttempts; ++a) {
      CanFrame commit;
      protocol::encode(protocol::TargetPositionZ{pose.position_mm.z(), protocol::TargetMode::pose, false,
                                                 pose_target_sequence(t, a)},
                       commit);
      std::printf("POSE_TARGET_Z_%d_%d=%s\nPOSE_TARGET_SEQUENCE_%d_%d=%02X\n", t, a, hex(commit).c_str(), t, a,
                  pose_target_sequence(t, a));
    }
  }
  return 0;
}

struct LoggedFrame {
  double time_s = 0;
  CanFrame frame;
};

// candump -L: "(1700000000.123456) vcan0 123#0011AA".
bool parse_candump_line(const std::string& line, LoggedFrame& logged) {
  std::istringstream in(line);
  std::string stamp, interface_name, body;
  if (!(in >> stamp >> interface_name >> body) || stamp.size() < 3) return false;
  logged.time_s = std::strtod(stamp.c_str() + 1, nullptr);
  const std::size_t hash = body.find('#');
  if (hash == std::string::npos || hash > 3 || body.size() > hash + 1 + 16 || (body.size() - hash - 1) % 2 != 0) {
    return false;  // extended, remote or CAN FD frames: not the protocol's
  }
  logged.frame.id = std::uint32_t(std::stoul(body.substr(0, hash), nullptr, 16));
  logged.frame.dlc = std::uint8_t((body.size() - hash - 1) / 2);
  for (int i = 0; i < logged.frame.dlc; ++i) {
    logged.frame.data[i] = std::uint8_t(std::stoul(body.substr(hash + 1 + 2 * i, 2), nullptr, 16));
  }
  return true;
}

struct Phase {
  std::vector<LoggedFrame> frames;
};

class Checker {
 public:
  explicit Checker(const Model& m) : model_(m) {}

  void expect(bool ok, const std::string& what) {
    std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
    if (!ok) ++failures_;
  }
  int failures() const { return failures_; }

  // Every decoded pose in the phase against compensated_forward on the
  // feedback cables; returns how many there were.
  int check_poses(const Phase& phase, const char* name) {
    model::ForwardResult<double> expected;
    model::compensated_forward(feedback_cables(model_), model_.geometry, model_.correction, expected);
    double worst_mm = 0, worst_rad = 0;
    int poses = 0, uncompensated = 0;
    // A pose is the three frames in a row, as the runtime sends them; a
    // triplet with a frame missing from the log is skipped, not misread.
    protocol::PosePositionXy xy;
    protocol::PosePositionZ z;
    protocol::PoseOrientation orientation;
    constexpr protocol::DecodeStatus ok = protocol::DecodeStatus::ok;
    int pose_frames_in_row = 0;
    for (const LoggedFrame& logged : phase.frames) {
      const CanFrame& f = logged.frame;
      if (protocol::decode(f, xy) == ok) {
        pose_frames_in_row = 1;
      } else if (protocol::decode(f, z) == ok) {
        pose_frames_in_row = pose_frames_in_row == 1 ? 2 : 0;
      }
      if (protocol::decode(f, orientation) != ok) continue;
      const bool complete = pose_frames_in_row == 2;
      pose_frames_in_row = 0;
      if (!complete) continue;
      model::Vec3<double> position(xy.x_mm, xy.y_mm, z.z_mm);
      Eigen::Quaterniond q(orientation.qw, orientation.qx, orientation.qy, orientation.qz);
      q.normalize();
      const Eigen::Quaterniond reference(expected.compensated.rotation);
      worst_mm = std::max(worst_mm, (position - expected.compensated.position_mm).norm());
      worst_rad = std::max(worst_rad, q.angularDistance(reference));
      if (!z.compensated) ++uncompensated;
      ++poses;
    }
    std::printf("%s: %d poses, worst position %.4f mm, worst orientation %.2e rad\n", name, poses, worst_mm, worst_rad);
    expect(worst_mm <= kPoseToleranceMm && worst_rad <= kOrientationToleranceRad,
           std::string(name) + ": poses match compensated_forward within quantisation");
    expect(uncompensated == 0, std::string(name) + ": every pose flagged compensated");
    return poses;
  }

 private:
  const Model& model_;
  int failures_ = 0;
};

std::vector<const LoggedFrame*> with_id(const Phase& phase, std::uint32_t id) {
  std::vector<const LoggedFrame*> out;
  for (const LoggedFrame& f : phase.frames) {
    if (f.frame.id == id) out.push_back(&f);
  }
  return out;
}

// A STATUS frame as decoded; one that does not decode (random traffic on its
// id) reads as BOOT without a fault, which no check looks for.
protocol::Status status_of(const LoggedFrame* f) {
  protocol::Status status;
  protocol::decode(f->frame, status);
  return status;
}

// A counter of the last STATS frame up to the phase; its fault detail is not read.
int last_stat(const std::vector<Phase>& phases, int upto_phase, std::int64_t protocol::Stats::*counter) {
  for (int p = upto_phase; p >= 0; --p) {
    const auto frames = with_id(phases[p], protocol::stats::kMessage.id);
    for (auto f = frames.rbegin(); f != frames.rend(); ++f) {
      protocol::Stats stats;
      if (protocol::decode((*f)->frame, FaultCode::none, stats) == protocol::DecodeStatus::ok) {
        return int(stats.*counter);
      }
    }
  }
  return -1;
}

int check(const Model& m, const std::string& log_path) {
  std::ifstream in(log_path);
  if (!in) {
    std::fprintf(stderr, "cannot open %s\n", log_path.c_str());
    return 1;
  }
  // phases[k]: frames after marker k (phase 0: before the first marker).
  std::vector<Phase> phases(1);
  std::string line;
  LoggedFrame logged;
  while (std::getline(in, line)) {
    if (!parse_candump_line(line, logged)) continue;
    // Random traffic may hit the marker's id; only the next number counts.
    if (logged.frame.id == kMarkerId && logged.frame.dlc == 1 && logged.frame.data[0] == phases.size()) {
      phases.resize(std::size_t(logged.frame.data[0]) + 1);
      continue;
    }
    phases.back().frames.push_back(logged);
  }
  Checker c(m);
  c.expect(phases.size() == 9, "all 8 markers in the log (got " + std::to_string(phases.size() - 1) + ")");
  if (phases.size() != 9) return 1;
  constexpr std::uint32_t kStatusId = protocol::status::kMessage.id;
  const auto state_of = [](const LoggedFrame* f) { return status_of(f).state; };
  // Under User-Mode Linux every system call is expensive and the feeders
  // share one virtual CPU with the runtime (and the host may be busy), so a
  // 1 kHz cycle misses releases and the input may go stale for a while even
  // as frames keep flowing. Phases with input therefore ask for RUN to be
  // reached, and the pose content is what is checked strictly.
  const auto reaches_run = [&](const Phase& phase, const char* name) {
    int run = 0, total = 0;
    for (const LoggedFrame* f : with_id(phase, kStatusId)) {
      run += state_of(f) == RuntimeState::run ? 1 : 0;
      ++total;
    }
    std::printf("%s: %d of %d STATUS frames in RUN\n", name, run, total);
    return run > 0;
  };

  // 0: no cable input yet: the runtime's heartbeat says its input is stale.
  const auto boot_status = with_id(phases[0], kStatusId);
  c.expect(!boot_status.empty() && state_of(boot_status.back()) == RuntimeState::fault &&
               status_of(boot_status.back()).fault == FaultCode::cable_input_stale,
           "before any cable frame: STATUS is FAULT, cable input stale");

  // 1: cable feedback flowing: RUN, poses equal the model's.
  {
    const int poses = c.check_poses(phases[1], "feedback");
    const double span_s = phases[1].frames.empty() ? 0 : phases[1].frames.back().time_s - phases[1].frames.front().time_s;
    std::printf("feedback: %.0f poses/s over %.2f s\n", span_s > 0 ? poses / span_s : 0.0, span_s);
    c.expect(poses >= 20, "feedback: poses published");
    c.expect(reaches_run(phases[1], "feedback"), "feedback: STATUS is RUN");
  }
  // 2: malformed frames: the rejected counter grows. Phase 4 holds the first
  // STATS certainly sent after the runtime read them (it answered the target
  // sent after them, and nothing is rejected once the feeders stop).
  {
    const int before = last_stat(phases, 1, &protocol::Stats::rejected_frames);
    const int after = last_stat(phases, 4, &protocol::Stats::rejected_frames);
    std::printf("malformed: rejected frames %d -> %d\n", before, after);
    c.expect(before >= 0 && after >= before + 4, "malformed: STATS rejected frames grew by the 4 sent");
    bool reported = false;
    for (int p = 2; p <= 3; ++p) {
      for (const LoggedFrame* f : with_id(phases[p], kStatusId)) {
        const FaultCode fault = status_of(f).fault;
        reported = reported || fault == FaultCode::cable_frame_malformed || fault == FaultCode::target_malformed;
      }
    }
    c.expect(reported, "malformed: STATUS reported the rejection");
    c.check_poses(phases[2], "malformed");
  }
  // 3: target -> IK_REPORT and setpoints whose kinematics reach the target.
  {
    const auto reports = with_id(phases[3], protocol::ik_report::kMessage.id);
    bool converged = false;
    for (const LoggedFrame* f : reports) {
      protocol::IkReport report;
      converged = converged || (protocol::decode(f->frame, report) == protocol::DecodeStatus::ok &&
                                report.sequence == kTargetSequence && report.outcome == protocol::IkOutcome::converged);
    }
    c.expect(converged, "target: IK_REPORT with the sequence, converged");
    model::CableVector<double> setpoints(4 * m.geometry.segment_count);
    int found = 0;
    for (int s = 0; s < m.geometry.segment_count; ++s) {
      const auto frames = with_id(phases[3], protocol::cable_setpoint::kMessage.id + std::uint32_t(s));
      protocol::CableSetpoint setpoint;
      if (frames.empty() || protocol::decode(frames.back()->frame, setpoint) != protocol::DecodeStatus::ok) continue;
      for (int k = 0; k < 4; ++k) setpoints[4 * s + k] = setpoint.lengths_mm[k];
      ++found;
    }
    c.expect(found == m.geometry.segment_count, "target: a CABLE_SETPOINT frame per segment");
    if (found == m.geometry.segment_count) {
      model::ForwardResult<double> reached;
      const model::Status s = model::compensated_forward(setpoints, m.geometry, m.correction, reached);
      const double error_mm = (reached.compensated.position_mm - target_position_mm(m)).norm();
      std::printf("target: setpoints reach the target within %.4f mm\n", error_mm);
      c.expect(s == model::Status::ok && error_mm <= kSetpointReachToleranceMm, "target: setpoints reach the target");
    }
  }
  // 4: feeders stopped: FAULT, and no pose after it.
  {
    const auto s = with_id(phases[4], kStatusId);
    const LoggedFrame* first_fault = nullptr;
    for (const LoggedFrame* f : s) {
      if (state_of(f) == RuntimeState::fault) {
        first_fault = f;
        break;
      }
    }
    c.expect(first_fault != nullptr && status_of(first_fault).fault == FaultCode::cable_input_stale,
             "stale: STATUS goes to FAULT, cable input stale");
    // A pose may follow a FAULT only if cable feedback came after it: under
    // load the input turns stale now and then before the feeders stop, and
    // the runtime rightly returns to RUN on the next complete set. After the
    // feeders stop, nothing may.
    int poses_after = 0;
    bool fault_without_input = false;
    for (const LoggedFrame& f : phases[4].frames) {
      if (protocol::status::kMessage.carries(f.frame.id) && state_of(&f) == RuntimeState::fault) {
        fault_without_input = true;
      } else if (protocol::cable_feedback::kMessage.carries(f.frame.id)) {
        fault_without_input = false;
      } else if (protocol::pose_orientation::kMessage.carries(f.frame.id) && fault_without_input) {
        ++poses_after;
      }
    }
    c.expect(first_fault != nullptr && poses_after == 0, "stale: no pose published in FAULT");
    const int stale_before = last_stat(phases, 3, &protocol::Stats::stale_events);
    const int stale_after = last_stat(phases, 4, &protocol::Stats::stale_events);
    std::printf("stale: stale events %d -> %d\n", stale_before, stale_after);
    c.expect(stale_before >= 0 && stale_after > stale_before, "stale: STATS stale events grew");
  }
  // 5: feeders resumed: back to RUN with the same poses.
  {
    c.expect(reaches_run(phases[5], "resume"), "resume: STATUS back to RUN");
    c.expect(c.check_poses(phases[5], "resume") >= 20, "resume: poses published again");
  }
  // 6: random traffic from cangen: the runtime keeps its heartbeat and counts what it refused.
  {
    const auto s = with_id(phases[6], kStatusId);
    std::printf("random traffic: %zu frames on the bus, %zu STATUS\n", phases[6].frames.size(), s.size());
    c.expect(s.size() >= 10, "random traffic: STATUS keeps coming");
    c.expect(last_stat(phases, 6, &protocol::Stats::rejected_frames) > last_stat(phases, 5, &protocol::Stats::rejected_frames), "random traffic: rejected frames grew");
  }
  // 7: after the noise: RUN and the feedback poses again.
  {
    const auto s = with_id(phases[7], kStatusId);
    c.expect(reaches_run(phases[7], "after traffic"), "after traffic: STATUS is RUN");
    c.expect(c.check_poses(phases[7], "after traffic") >= 10, "after traffic: poses published");
    if (!s.empty()) {
      std::printf("last STATUS: overruns %lld, execution max %lld us, mean %lld us; jitter max %d us\n",
                  (long long)status_of(s.back()).overruns, (long long)status_of(s.back()).exec_max_us,
                  (long long)status_of(s.back()).exec_mean_us, last_stat(phases, 7, &protocol::Stats::jitter_max_us));
    }
  }
  // 8: pose targets one after another: every attempt sent gets exactly one
  // final IK_REPORT (in_progress ones aside), each target's last attempt
  // converged, and poses kept coming while it was solved.
  {
    const std::uint32_t commit_id = protocol::target_position_z::kMessage.id;
    const std::uint32_t report_id = protocol::ik_report::kMessage.id;
    const std::uint32_t pose_id = protocol::pose_orientation::kMessage.id;
    for (int t = 0; t < kPoseTargets; ++t) {
      int attempts = 0;
      bool converged = false;
      for (int a = 0; a < kPoseTargetAttempts; ++a) {
        const std::uint8_t sequence = pose_target_sequence(t, a);
        double committed_s = -1;
        for (const LoggedFrame& f : phases[8].frames) {
          protocol::TargetPositionZ commit;
          if (f.frame.id == commit_id && protocol::decode(f.frame, commit) == protocol::DecodeStatus::ok &&
              commit.sequence == sequence) {
            committed_s = f.time_s;
            break;
          }
        }
        if (committed_s < 0) continue;
        ++attempts;
        int finals = 0, poses = 0;
        protocol::IkReport final_report;
        bool ended = false;
        for (const LoggedFrame& f : phases[8].frames) {
          if (f.time_s < committed_s) continue;
          protocol::IkReport report;
          if (f.frame.id == report_id && protocol::decode(f.frame, report) == protocol::DecodeStatus::ok &&
              report.sequence == sequence && report.outcome != protocol::IkOutcome::in_progress) {
            ++finals;
            if (!ended) final_report = report;
            ended = true;
          }
          if (!ended && f.frame.id == pose_id) ++poses;
        }
        const std::string name = "pose target " + std::to_string(t) + " attempt " + std::to_string(a);
        c.expect(finals == 1, name + ": exactly one final IK_REPORT (got " + std::to_string(finals) + ")");
        if (finals == 0) continue;
        std::printf("%s: outcome %d after %d cycles, %d iterations, %.4f mm / %.2g rad; %d poses meanwhile\n",
                    name.c_str(), int(final_report.outcome), final_report.cycles, final_report.iterations,
                    final_report.position_residual_mm, final_report.orientation_residual_rad, poses);
        if (final_report.outcome == protocol::IkOutcome::converged) {
          converged = true;
          // At least one pose every other cycle of the solve: the solve's
          // work is spread over cycles, and each cycle still publishes.
          c.expect(poses >= 1 && 2 * poses >= final_report.cycles,
                   name + ": poses kept coming during the solve (" + std::to_string(poses) + " in " +
                       std::to_string(final_report.cycles) + " cycles)");
        }
      }
      c.expect(attempts > 0, "pose target " + std::to_string(t) + ": sent");
      c.expect(converged, "pose target " + std::to_string(t) + ": converged");
    }
  }
  std::printf("%d check(s) failed\n", c.failures());
  return c.failures() == 0 ? 0 : 1;
}

// One line per target: POSE_TARGET_<k>=x y z qw qx qy qz (mm; w >= 0).
int print_pose_targets(const Model& m) {
  for (int t = 0; t < int(std::size(kPoseTargetBends)); ++t) {
    const model::Pose<double> pose = pose_target(m, t);
    Eigen::Quaterniond q(pose.rotation);
    q.normalize();
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    std::printf("POSE_TARGET_%d=%.4f %.4f %.4f %.6f %.6f %.6f %.6f\n", t, pose.position_mm.x(), pose.position_mm.y(),
                pose.position_mm.z(), q.w(), q.x(), q.y(), q.z());
  }
  return 0;
}

// The FD test's client encodes from physical values with the DBC: the
// feedback lengths and the target as on the bus (0.01 mm).
int print_fd_values(const Model& m) {
  const model::CableVector<double> cables = feedback_cables(m);
  std::printf("SEGMENTS=%d\n", m.geometry.segment_count);
  for (int s = 0; s < m.geometry.segment_count; ++s) {
    std::printf("FEEDBACK_MM_%d=%.2f %.2f %.2f %.2f\n", s, cables[4 * s], cables[4 * s + 1], cables[4 * s + 2],
                cables[4 * s + 3]);
  }
  const model::Vec3<double> target = target_position_mm(m);
  std::printf("TARGET_MM=%.2f %.2f %.2f\n", target.x(), target.y(), target.z());
  return 0;
}

// fd_client.py's summary: "pose x y z qw qx qy qz" per compensated POSE_FD,
// then "setpoints" with every cable's last commanded length. Every pose
// must be compensated_forward of the feedback, and the setpoints must reach
// the streamed target.
int check_fd(const Model& m, const std::string& summary_path) {
  std::ifstream in(summary_path);
  if (!in) {
    std::fprintf(stderr, "cannot open %s\n", summary_path.c_str());
    return 1;
  }
  Checker c(m);
  model::ForwardResult<double> expected;
  model::compensated_forward(feedback_cables(m), m.geometry, m.correction, expected);
  const Eigen::Quaterniond reference(expected.compensated.rotation);
  double worst_mm = 0, worst_rad = 0;
  int poses = 0;
  std::vector<double> setpoints;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string kind;
    fields >> kind;
    std::vector<double> numbers;
    for (double v; fields >> v;) numbers.push_back(v);
    if (kind == "pose" && numbers.size() == 7) {
      const model::Vec3<double> position(numbers[0], numbers[1], numbers[2]);
      Eigen::Quaterniond q(numbers[3], numbers[4], numbers[5], numbers[6]);
      q.normalize();
      worst_mm = std::max(worst_mm, (position - expected.compensated.position_mm).norm());
      worst_rad = std::max(worst_rad, q.angularDistance(reference));
      ++poses;
    } else if (kind == "setpoints") {
      setpoints = numbers;
    } else {
      c.expect(false, "summary line: " + line);
    }
  }
  std::printf("fd: %d poses, worst position %.4f mm, worst orientation %.2e rad\n", poses, worst_mm, worst_rad);
  c.expect(poses > 0 && worst_mm <= kPoseToleranceMm && worst_rad <= kOrientationToleranceRad,
           "fd: POSE_FD poses match compensated_forward within quantisation");
  const bool complete = setpoints.size() == std::size_t(4 * m.geometry.segment_count);
  c.expect(complete, "fd: the setpoints of every segment");
  if (complete) {
    model::CableVector<double> lengths(setpoints.size());
    for (std::size_t i = 0; i < setpoints.size(); ++i) lengths[Eigen::Index(i)] = setpoints[i];
    model::ForwardResult<double> reached;
    const model::Status s = model::compensated_forward(lengths, m.geometry, m.correction, reached);
    const double error_mm = (reached.compensated.position_mm - target_position_mm(m)).norm();
    std::printf("fd: setpoints reach the target within %.4f mm\n", error_mm);
    c.expect(s == model::Status::ok && error_mm <= kSetpointReachToleranceMm, "fd: setpoints reach the target");
  }
  std::printf("%d check(s) failed\n", c.failures());
  return c.failures() == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string command = argc > 1 ? argv[1] : "";
  if (command == "image" && argc == 3) return write_image(argv[2]);
  if (command == "image" && argc == 5) {
    return write_image(argv[2], std::atoi(argv[3]), static_cast<std::uint32_t>(std::strtoul(argv[4], nullptr, 10)));
  }
  Model m;
  const bool with_image = ((command == "frames" || command == "fd-values" || command == "pose-targets") && argc == 3) ||
                          ((command == "check" || command == "fd-check") && argc == 4);
  if (with_image) {
    if (!load_model(argv[2], m)) {
      std::fprintf(stderr, "socketcan_check: %s: not a usable model image\n", argv[2]);
      return 1;
    }
    if (command == "frames") return print_frames(m);
    if (command == "fd-values") return print_fd_values(m);
    if (command == "pose-targets") return print_pose_targets(m);
    return command == "check" ? check(m, argv[3]) : check_fd(m, argv[3]);
  }
  std::fprintf(stderr,
               "usage: socketcan_check image <out> [points seed] | frames <image> | check <image> <candump log> | "
               "fd-values <image> | fd-check <image> <summary> | pose-targets <image>\n");
  return 2;
}
