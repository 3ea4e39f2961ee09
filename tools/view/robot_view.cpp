#include "view/robot_view.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <cdcr/firmware/protocol/fd_frames.hpp>
#include <cdcr/firmware/protocol/frames.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/hal/shifted_can_bus.hpp>
#include <cdcr/model/chain.hpp>
#include <cdcr/model/unit_quaternion.hpp>

#include "sim/simulated_platform.hpp"

namespace cdcr::view {

namespace fw = cdcr::firmware;
namespace model = cdcr::model;
namespace protocol = cdcr::firmware::protocol;
using nlohmann::json;

namespace {

constexpr double kMetresPerMm = 1e-3;

json stamp(std::uint64_t time_ns) {
  return json{{"sec", time_ns / 1000000000u}, {"nsec", time_ns % 1000000000u}};
}
json vector_json(const model::Vec3<double>& v_mm) {
  return json{{"x", v_mm.x() * kMetresPerMm}, {"y", v_mm.y() * kMetresPerMm}, {"z", v_mm.z() * kMetresPerMm}};
}
json quaternion_json(const Eigen::Quaterniond& q) { return json{{"x", q.x()}, {"y", q.y()}, {"z", q.z()}, {"w", q.w()}}; }
json pose_json(const model::Pose<double>& pose) {
  return json{{"position", vector_json(pose.position_mm)},
              {"orientation", quaternion_json(model::canonical_quaternion(pose.rotation))}};
}
json at_origin() { return pose_json(model::Pose<double>{}); }
json rgba(double r, double g, double b, double a) { return json{{"r", r}, {"g", g}, {"b", b}, {"a", a}}; }

// A SceneEntity with every primitive list present (Foxglove's 3D panel
// reads them all).
json entity(const char* id, std::uint64_t time_ns) {
  return json{{"timestamp", stamp(time_ns)}, {"frame_id", "base"},          {"id", id},
              {"lifetime", {{"sec", 0}, {"nsec", 0}}},
              {"frame_locked", false},   {"metadata", json::array()},     {"arrows", json::array()},
              {"cubes", json::array()},  {"spheres", json::array()},      {"cylinders", json::array()},
              {"lines", json::array()},  {"triangles", json::array()},    {"texts", json::array()},
              {"models", json::array()}};
}

json sphere(const model::Vec3<double>& center_mm, double diameter_mm, const json& color) {
  model::Pose<double> pose;
  pose.position_mm = center_mm;
  const double d = diameter_mm * kMetresPerMm;
  return json{{"pose", pose_json(pose)}, {"size", {{"x", d}, {"y", d}, {"z", d}}}, {"color", color}};
}

// A LINE_STRIP through `points` (already in metres), in the base frame.
json line_strip(json points, double thickness_mm, const json& color) {
  return json{{"type", 0},
              {"pose", at_origin()},
              {"thickness", thickness_mm * kMetresPerMm},
              {"scale_invariant", false},
              {"points", std::move(points)},
              {"color", color},
              {"colors", json::array()},
              {"indices", json::array()}};
}

// A frame's three axes as red, green and blue lines from its origin.
void add_axes(json& lines, const model::Pose<double>& frame, double length_mm, double thickness_mm) {
  const json colors[3] = {rgba(0.9, 0.1, 0.1, 1), rgba(0.1, 0.75, 0.1, 1), rgba(0.15, 0.3, 0.95, 1)};
  for (int axis = 0; axis < 3; ++axis) {
    const model::Vec3<double> end = frame.position_mm + length_mm * frame.rotation.col(axis);
    lines.push_back(line_strip({vector_json(frame.position_mm), vector_json(end)}, thickness_mm, colors[axis]));
  }
}

const char* outcome_name(protocol::IkOutcome outcome) {
  for (const auto& entry : protocol::values::kIkOutcome) {
    if (entry.value == static_cast<std::uint32_t>(outcome)) return entry.name;
  }
  return "unknown";
}

}  // namespace

struct RobotView::State {
  explicit State(const std::vector<std::uint8_t>& image) : runtime((platform.storage.assign(image), platform.hal),
                                                                   fw::Geometry::prototype()) {}
  sim::SimulatedPlatform platform;
  fw::Runtime runtime;
  fw::HysteresisTracker tracker;
  model::RobotGeometry<double> geometry;
  fw::Cables feedback, setpoints;
  std::vector<bool> segment_seen;
  bool has_setpoints = false;
  // The target's frames until its commit (TARGET_POSITION_Z), and the last
  // committed one.
  protocol::TargetPositionXy pending_xy;
  protocol::TargetOrientation pending_orientation;
  bool has_target = false, target_is_pose = false;
  model::Pose<double> target;
  // The latest estimate of a complete cable set, and its bend in double
  // (the backbone is drawn from it and ends at nominal_tip).
  fw::PoseEstimate estimate;
  model::JointVector<double> bend;
  model::PoseUncertainty<fw::Scalar> uncertainty;
  model::Pose<double> nominal_tip;
  std::uint64_t next_scene_ns = 0;
};

RobotView::RobotView(const std::vector<std::uint8_t>& image, const ViewOptions& options, ViewSink& sink)
    : state_(std::make_unique<State>(image)), options_(options), sink_(sink) {
  if (!(options.scene_rate_hz > 0)) throw std::invalid_argument("the view's scene rate must be positive");
  State& s = *state_;
  const fw::RuntimeState booted = s.runtime.init();
  if (booted != fw::RuntimeState::run && booted != fw::RuntimeState::degraded) {
    throw std::runtime_error(std::string("the view cannot use the image: ") + fw::to_string(s.runtime.boot_fault()));
  }
  if (booted == fw::RuntimeState::degraded) {
    note_ = std::string("the image is not used (") + fw::to_string(s.runtime.boot_fault()) +
            "): the view shows the nominal model of the prototype's geometry, as the runtime runs";
  }
  s.tracker = s.runtime.hysteresis();
  s.geometry = s.runtime.geometry().cast<double>();
  s.feedback.setZero(s.geometry.cable_count());
  s.setpoints.setZero(s.geometry.cable_count());
  s.segment_seen.assign(s.geometry.segment_count, false);
}

RobotView::~RobotView() = default;

int RobotView::segment_count() const { return state_->geometry.segment_count; }

void RobotView::on_frame(const hal::CanFrame& wire_frame, std::uint64_t time_ns) {
  ++frames_;
  hal::CanFrame frame = wire_frame;
  frame.id = hal::ShiftedCanBus::unshifted(wire_frame.id, options_.id_offset);
  if (take_cables(frame, time_ns) || take_target(frame, time_ns)) return;
  take_report(frame, time_ns);
}

bool RobotView::decoded(protocol::DecodeStatus status) {
  if (status == protocol::DecodeStatus::ok) return true;
  if (status != protocol::DecodeStatus::wrong_id) ++malformed_;
  return false;
}

// A segment's cables from its frame into `into`; false for a segment the
// image's robot does not have.
bool RobotView::take_segment(const double* lengths_mm, int segment, fw::Cables& into) const {
  const State& s = *state_;
  if (segment < 0 || segment >= s.geometry.segment_count) return false;
  const int first = s.geometry.first_cable(segment);
  for (int k = 0; k < s.geometry.segments[segment].cables.count; ++k) {
    into[first + k] = static_cast<fw::Scalar>(lengths_mm[k]);
  }
  return true;
}

bool RobotView::take_cables(const hal::CanFrame& frame, std::uint64_t time_ns) {
  State& s = *state_;
  protocol::CableFeedback feedback;
  if (decoded(protocol::decode(frame, feedback))) {
    if (!take_segment(feedback.lengths_mm, feedback.segment, s.feedback)) return true;
    s.segment_seen[feedback.segment] = true;
    if (feedback.segment == s.geometry.segment_count - 1) {
      bool complete = true;
      for (bool seen : s.segment_seen) complete = complete && seen;
      if (complete) on_feedback_complete(time_ns);
    }
    return true;
  }
  protocol::CableSetpoint setpoint;
  if (decoded(protocol::decode(frame, setpoint))) {
    s.has_setpoints = take_segment(setpoint.lengths_mm, setpoint.segment, s.setpoints) || s.has_setpoints;
    return true;
  }
  protocol::CableSetpointsFd setpoints_fd;
  if (decoded(protocol::decode(frame, setpoints_fd))) {
    for (int k = 0; k < setpoints_fd.segment_count; ++k) {
      const protocol::CableSetpoint& part = setpoints_fd.segments[k];
      s.has_setpoints = take_segment(part.lengths_mm, part.segment, s.setpoints) || s.has_setpoints;
    }
    return true;
  }
  protocol::Homing homing;
  if (decoded(protocol::decode(frame, homing))) {
    if (homing.at_home) s.tracker.homed(s.runtime.geometry());
    return true;
  }
  return false;
}

// The target's frames until its commit (TARGET_POSITION_Z), or TARGET_FD.
bool RobotView::take_target(const hal::CanFrame& frame, std::uint64_t time_ns) {
  State& s = *state_;
  const auto commit = [&](const protocol::TargetPositionXy& xy, const protocol::TargetPositionZ& z,
                          const protocol::TargetOrientation& q) {
    s.has_target = true;
    s.target_is_pose = z.mode == protocol::TargetMode::pose;
    s.target.position_mm = model::Vec3<double>(xy.x_mm, xy.y_mm, z.z_mm);
    s.target.rotation = s.target_is_pose ? Eigen::Quaterniond(q.qw, q.qx, q.qy, q.qz).normalized().toRotationMatrix()
                                         : model::Mat3<double>::Identity();
    json message{{"timestamp", stamp(time_ns)}, {"frame_id", "base"}, {"pose", pose_json(s.target)}};
    sink_.publish(Topic::target, time_ns, message.dump());
  };
  protocol::TargetPositionXy xy;
  if (decoded(protocol::decode(frame, xy))) {
    s.pending_xy = xy;
    return true;
  }
  protocol::TargetOrientation orientation;
  if (decoded(protocol::decode(frame, orientation))) {
    s.pending_orientation = orientation;
    return true;
  }
  protocol::TargetPositionZ z;
  if (decoded(protocol::decode(frame, z))) {
    commit(s.pending_xy, z, s.pending_orientation);
    return true;
  }
  protocol::TargetFd target_fd;
  if (decoded(protocol::decode(frame, target_fd))) {
    commit(target_fd.position_xy, target_fd.position_z, target_fd.orientation);
    return true;
  }
  return false;
}

// STATUS and IK_REPORT, as decoded.
void RobotView::take_report(const hal::CanFrame& frame, std::uint64_t time_ns) {
  protocol::Status status;
  if (decoded(protocol::decode(frame, status))) {
    json message{{"timestamp", stamp(time_ns)},
                 {"state", fw::to_string(status.state)},
                 {"fault", fw::to_string(status.fault)},
                 {"fault_code", static_cast<int>(status.fault)},
                 {"overruns", status.overruns},
                 {"exec_max_us", status.exec_max_us},
                 {"exec_mean_us", status.exec_mean_us},
                 {"extrapolating", status.extrapolating},
                 {"hysteresis_unknown", status.hysteresis_unknown}};
    sink_.publish(Topic::status, time_ns, message.dump());
    return;
  }
  protocol::IkReport report;
  if (decoded(protocol::decode(frame, report))) {
    json message{{"timestamp", stamp(time_ns)},
                 {"sequence", report.sequence},
                 {"outcome", outcome_name(report.outcome)},
                 {"iterations", report.iterations},
                 {"cycles", report.cycles},
                 {"position_residual_mm", report.position_residual_mm},
                 {"orientation_residual_rad", report.orientation_residual_rad}};
    sink_.publish(Topic::ik_report, time_ns, message.dump());
  }
}

void RobotView::on_feedback_complete(std::uint64_t time_ns) {
  State& s = *state_;
  const int cables = s.geometry.cable_count();
  json feedback = json::array(), setpoints = json::array(), following = json::array();
  double largest_mm = 0;
  for (int c = 0; c < cables; ++c) {
    feedback.push_back(double(s.feedback[c]));
    setpoints.push_back(double(s.setpoints[c]));
    const double error_mm = double(s.setpoints[c]) - double(s.feedback[c]);
    following.push_back(error_mm);
    largest_mm = std::max(largest_mm, std::abs(error_mm));
  }
  sink_.publish(Topic::cables, time_ns,
                json{{"timestamp", stamp(time_ns)},
                     {"feedback_mm", feedback},
                     {"setpoints_mm", setpoints},
                     {"has_setpoints", s.has_setpoints}}
                    .dump());
  if (s.has_setpoints) {
    sink_.publish(Topic::following_error, time_ns,
                  json{{"timestamp", stamp(time_ns)}, {"cables_mm", following}, {"largest_mm", largest_mm}}.dump());
  }

  // The lengths the pose is estimated on: the board's, through the
  // hysteresis tracker when the image has one.
  const fw::Cables& effective = s.tracker.track(s.feedback);
  fw::PoseEstimate estimate;
  if (s.runtime.estimate_pose(effective, estimate) != model::Status::ok) return;
  s.estimate = estimate;
  s.uncertainty = s.runtime.estimate_uncertainty(estimate);
  s.bend = model::bend_from_joints(estimate.joints).cast<double>();
  s.nominal_tip = model::forward_kinematics_bend(s.bend, s.geometry);
  const model::Pose<double> tip = estimate.pose.cast<double>();
  sink_.publish(Topic::tip_pose, time_ns,
                json{{"timestamp", stamp(time_ns)}, {"frame_id", "base"}, {"pose", pose_json(tip)}}.dump());
  sink_.publish(Topic::nominal_tip_pose, time_ns,
                json{{"timestamp", stamp(time_ns)}, {"frame_id", "base"}, {"pose", pose_json(s.nominal_tip)}}.dump());
  sink_.publish(Topic::tip_uncertainty, time_ns,
                json{{"timestamp", stamp(time_ns)},
                     {"r95_mm", double(s.uncertainty.r95_mm)},
                     {"r95_deg", double(s.uncertainty.r95_deg)},
                     {"extrapolating", bool(s.uncertainty.extrapolating)},
                     {"outside_range", estimate.outside_range},
                     {"compensated", estimate.compensated}}
                    .dump());
  if (time_ns >= s.next_scene_ns) {
    publish_scene(time_ns);
    const auto period_ns = static_cast<std::uint64_t>(std::llround(1e9 / options_.scene_rate_hz));
    s.next_scene_ns = (s.next_scene_ns == 0 || time_ns - s.next_scene_ns >= period_ns) ? time_ns + period_ns
                                                                                        : s.next_scene_ns + period_ns;
  }
}

void RobotView::publish_scene(std::uint64_t time_ns) {
  State& s = *state_;
  ++scenes_;
  const model::Pose<double> tip = s.estimate.pose.cast<double>();
  double total_length_mm = 0;
  for (int i = 0; i < s.geometry.segment_count; ++i) total_length_mm += s.geometry.segments[i].backbone_length_mm;

  // The backbone: one line strip per segment, its nominal arc.
  json backbone = entity("backbone", time_ns);
  const json segment_colors[2] = {rgba(0.95, 0.6, 0.1, 1), rgba(0.2, 0.55, 0.95, 1)};
  model::Pose<double> segment_base;
  const int n = std::max(2, options_.points_per_segment);
  for (int i = 0; i < s.geometry.segment_count; ++i) {
    const model::Vec2<double> segment_bend = s.bend.segment<2>(2 * i);
    const double length_mm = s.geometry.segments[i].backbone_length_mm;
    json points = json::array();
    for (int k = 0; k <= n; ++k) {
      const double fraction = double(k) / double(n);
      const model::Pose<double> along = segment_base * model::segment_pose<double>(fraction * segment_bend, fraction * length_mm);
      points.push_back(vector_json(along.position_mm));
    }
    backbone["lines"].push_back(line_strip(std::move(points), 0.025 * total_length_mm, segment_colors[i % 2]));
    segment_base = segment_base * model::segment_pose<double>(segment_bend, length_mm);
  }
  // The base frame and the compensated tip's.
  add_axes(backbone["lines"], model::Pose<double>{}, 0.15 * total_length_mm, 0.015 * total_length_mm);
  add_axes(backbone["lines"], tip, 0.06 * total_length_mm, 0.005 * total_length_mm);

  // The tip: the compensated one (small, so that its r95 sphere shows
  // around it), red when extrapolating; the nominal one grey, where the
  // backbone ends. Sizes in shares of the robot's length.
  json tip_entity = entity("tip", time_ns);
  const bool extrapolating = s.uncertainty.extrapolating;
  const json tip_color = extrapolating ? rgba(0.9, 0.1, 0.1, 1) : rgba(0.1, 0.7, 0.3, 1);
  const double marker_mm = 0.012 * total_length_mm;
  tip_entity["spheres"].push_back(sphere(tip.position_mm, marker_mm, tip_color));
  const double r95_mm = double(s.uncertainty.r95_mm);
  if (std::isfinite(r95_mm) && r95_mm > 0) {
    tip_entity["spheres"].push_back(sphere(tip.position_mm, 2 * r95_mm,
                                           extrapolating ? rgba(0.9, 0.1, 0.1, 0.3) : rgba(0.1, 0.7, 0.3, 0.25)));
  }
  tip_entity["spheres"].push_back(sphere(s.nominal_tip.position_mm, 0.035 * total_length_mm, rgba(0.6, 0.6, 0.6, 1)));
  json update{{"deletions", json::array()}, {"entities", json::array({backbone, tip_entity})}};
  json transforms = json::array();
  const auto transform = [&](const char* child, const model::Pose<double>& pose) {
    transforms.push_back({{"timestamp", stamp(time_ns)},
                          {"parent_frame_id", "base"},
                          {"child_frame_id", child},
                          {"translation", vector_json(pose.position_mm)},
                          {"rotation", quaternion_json(model::canonical_quaternion(pose.rotation))}});
  };
  transform("tip", tip);
  transform("nominal_tip", s.nominal_tip);
  if (s.has_target) {
    json target = entity("target", time_ns);
    // A halo: the tip sits inside it once it has reached the target.
    target["spheres"].push_back(sphere(s.target.position_mm, 0.04 * total_length_mm, rgba(0.95, 0.8, 0.1, 0.35)));
    if (s.target_is_pose) add_axes(target["lines"], s.target, 0.07 * total_length_mm, 0.008 * total_length_mm);
    update["entities"].push_back(target);
    transform("target", s.target);
  }
  sink_.publish(Topic::scene, time_ns, update.dump());
  sink_.publish(Topic::transforms, time_ns, json{{"transforms", transforms}}.dump());
}

}  // namespace cdcr::view
