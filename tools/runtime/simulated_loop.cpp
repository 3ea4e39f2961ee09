// cdcr-runtime --sim: the closed loop with the simulated drives and robot.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include <cdcr/firmware/runtime.hpp>
#include <cdcr/model/compensation.hpp>
#include <cdcr/model/hysteresis.hpp>
#include <cdcr/sim/lockstep_timer.hpp>
#include <cdcr/sim/virtual_can.hpp>

#include "bus_tally.hpp"
#include "export/binary_file.hpp"
#include "runtime_modes.hpp"
#include "sim/simulated_drives.hpp"
#include "sim/simulated_platform.hpp"
#include "sim/simulated_robot.hpp"
#include "sim/target_frames.hpp"
#include "sim/uniform_bend.hpp"

namespace cdcr::runtime_host {

namespace fw = cdcr::firmware;
namespace model = cdcr::model;
namespace protocol = cdcr::firmware::protocol;
namespace sim = cdcr::sim;

namespace {

// The board's buses as `choice` has them: CAN FD where asked for, timed at
// its bit rates (untimed at 0), the image in the model region.
sim::SimulatedPlatform& prepared(sim::SimulatedPlatform& platform, const std::string& image_path,
                                 const BusChoice& choice) {
  if (!image_path.empty()) platform.storage.assign(cdcr::exporting::read_binary_file(image_path));
  const cli::BusLayout& layout = choice.layout;
  const auto set_up = [&](sim::VirtualCanBus& bus, const cli::BusLine& line) {
    bus.set_fd(line.format != cdcr::hal::CanFormat::classical);
    if (line.bitrate > 0) bus.set_timing(platform.clock, {line.bitrate, line.data_bitrate});
  };
  set_up(platform.bus, layout.bus);
  if (layout.drives_bus) set_up(platform.drives_bus, layout.drives);
  return platform;
}

fw::Runtime& booted(fw::Runtime& runtime, const BusChoice& choice) {
  const cli::BusLayout& layout = choice.layout;
  if (!runtime.set_can_formats(layout.bus.format, layout.drives_bus ? layout.drives.format : layout.bus.format)) {
    throw std::runtime_error("the simulated buses refused the runtime's CAN formats");
  }
  runtime.init();
  return runtime;
}

sim::SimulatorConfig robot_config(const SimulatedRobotChoice& choice) {
  sim::SimulatorConfig config = choice.ideal_robot ? sim::SimulatorConfig::nominal_only() : sim::SimulatorConfig{};
  config.hysteresis.enabled = choice.hysteresis;
  return config;
}

// The runtime on the simulated board (with the image, if one is given), and
// the simulated robot whose cables it reads and moves.
struct SimulatedLoop {
  SimulatedLoop(const std::string& image_path, const SimulatedRobotChoice& choice, const BusChoice& bus_choice)
      : platform(protocol::id_offset(bus_choice.id_base), bus_choice.layout.drives_bus),
        runtime(prepared(platform, image_path, bus_choice).hal, fw::Geometry::prototype()),
        geometry(booted(runtime, bus_choice).geometry().cast<double>()),
        robot(geometry, robot_config(choice)),
        bus(bus_choice),
        drives_node(drives_bus().node(1), protocol::id_offset(bus_choice.id_base)),
        host_node(platform.bus.node(2), protocol::id_offset(bus_choice.id_base)),
        homing_node(drives_bus().node(2), protocol::id_offset(bus_choice.id_base)),
        drives_can(drives_node),
        host_can(host_node),
        homing_can(homing_node) {
    const cli::BusLayout& layout = bus.layout;
    drives_can.set_format(layout.drives_bus ? layout.drives.format : layout.bus.format);
    homing_can.set_format(layout.drives_bus ? layout.drives.format : layout.bus.format);
    host_can.set_format(layout.bus.format);
    runtime.set_publish_rates(bus.rates);
    for (BusTally* tally : {&bus_tally, &drives_tally}) tally->set_id_offset(protocol::id_offset(bus.id_base));
    if (platform.bus.timed()) platform.bus.set_observer(&bus_tally);
    if (layout.drives_bus && platform.drives_bus.timed()) platform.drives_bus.set_observer(&drives_tally);
    if (bus.view.wanted()) {
      // The view listens on the buses' one free node.
      std::vector<cdcr::hal::CanBus*> listeners{&platform.bus.node(3)};
      if (layout.drives_bus) listeners.push_back(&platform.drives_bus.node(3));
      view = std::make_unique<BusView>(image_path, bus.view, protocol::id_offset(bus.id_base), listeners);
    }
  }

  // Ends the view's run: prints its figures and where the recording is.
  void finish_view() {
    if (view) {
      view->take_frames(platform.clock.now_ns());
      view->finish();
    }
  }

  // The bus the drives are on: their own, or the host's.
  sim::VirtualCanBus& drives_bus() { return bus.layout.drives_bus ? platform.drives_bus : platform.bus; }

  void set_releases(std::int64_t first_release_ns, std::int64_t period_ns) {
    for (BusTally* tally : {&bus_tally, &drives_tally}) tally->set_releases(first_release_ns, period_ns);
  }

  // What the timed buses carried, against the budget's worst case (nothing
  // on an untimed bus).
  void print_bus_report(double rate_hz, bool streaming) const {
    if (!platform.bus.timed()) return;
    std::vector<TimedBus> buses{{&platform.bus, &bus_tally}};
    if (bus.layout.drives_bus) buses.push_back({&platform.drives_bus, &drives_tally});
    std::fputs(timed_bus_report(buses, platform.clock.now_ns(), geometry.segment_count, rate_hz, streaming, bus).c_str(),
               stdout);
  }

  sim::SimulatedPlatform platform;
  fw::Runtime runtime;
  model::RobotGeometry<double> geometry;
  sim::SimulatedRobot robot;
  BusChoice bus;
  // The drives' and the host's nodes, at the runtime's identifiers, in their
  // buses' formats; the homing move's setpoints come from a node on the
  // drives' bus.
  cdcr::hal::ShiftedCanBus drives_node;
  cdcr::hal::ShiftedCanBus host_node;
  cdcr::hal::ShiftedCanBus homing_node;
  cdcr::hal::FormattedCanBus drives_can;
  cdcr::hal::FormattedCanBus host_can;
  cdcr::hal::FormattedCanBus homing_can;
  BusTally bus_tally;
  BusTally drives_tally;
  std::unique_ptr<BusView> view;
};

// The simulated drives on the loop's bus, the host's node that sends the
// targets, and the lockstep timer at the cycle rate: what every closed-loop
// run starts with.
struct DrivenLoop {
  DrivenLoop(SimulatedLoop& loop, const model::CableVector<double>& start_cables, double rate_hz)
      : loop(loop),
        drives(loop.drives_can, start_cables, 50.0, sim::cables_per_segment(loop.geometry)),
        effective_cables(loop.robot.move_cables(drives.cables_mm())),
        host(loop.host_can),
        period_ns(static_cast<std::int64_t>(std::llround(1e9 / rate_hz))),
        dt_s(double(period_ns) * 1e-9) {
    host.set_filters(&protocol::kIkReportFrames, 1);
  }

  void start_timer() {
    loop.set_releases(loop.platform.clock.now_ns() + period_ns, period_ns);
    loop.platform.timer.start(period_ns);
  }

  // Waits for the next tick and moves the drives, and the robot's cables
  // with them, one period on.
  cdcr::hal::TimerTick advance_drives() {
    if (loop.view) loop.view->take_frames(loop.platform.clock.now_ns());
    const cdcr::hal::TimerTick tick = loop.platform.timer.wait_next();
    drives.step(dt_s);
    effective_cables = loop.robot.move_cables(drives.cables_mm());
    return tick;
  }

  // The host reads what the runtime sent, so that its queue never fills.
  void drain_host() {
    cdcr::hal::CanFrame frame;
    while (host.receive(frame) == cdcr::hal::CanStatus::ok) {
    }
  }

  SimulatedLoop& loop;
  sim::SimulatedCableDrives drives;
  // The lengths that bend the segments: the drives' through the friction,
  // which follows every step of the drives (the drives' own with it off).
  model::CableVector<double> effective_cables;
  cdcr::hal::FormattedCanBus& host;
  std::int64_t period_ns;
  double dt_s;
};

// The sum and the largest of a run of errors, in mm.
struct ErrorTally {
  double sum_mm = 0;
  double max_mm = 0;
  void add(double error_mm) {
    sum_mm += error_mm;
    max_mm = std::max(max_mm, error_mm);
  }
};

// A target as the host sends it: one TARGET_FD on an FD bus, else its
// classical frames.
void send_target(cdcr::hal::FormattedCanBus& host, const model::Vec3<double>& target_mm, std::uint8_t sequence) {
  model::Pose<double> target;
  target.position_mm = target_mm;
  for (const cdcr::hal::CanFrame& frame :
       host.fd() ? std::vector<cdcr::hal::CanFrame>{sim::target_fd_frame(target, protocol::TargetMode::position, false,
                                                                          sequence)}
                 : sim::target_frames(target_mm, protocol::TargetMode::position, false, sequence)) {
    host.send(frame);
  }
}

void send_pose_target(cdcr::hal::FormattedCanBus& host, const model::Pose<double>& target, std::uint8_t sequence,
                      bool tracking) {
  for (const cdcr::hal::CanFrame& frame :
       host.fd() ? std::vector<cdcr::hal::CanFrame>{sim::target_fd_frame(target, protocol::TargetMode::pose, tracking,
                                                                          sequence)}
                 : sim::target_frames(target, protocol::TargetMode::pose, tracking, sequence)) {
    host.send(frame);
  }
}

// The start-up of a robot whose cables have friction, as a real robot's:
// the drives take the cables through the homing move (model::
// homing_waypoints: the approach, every segment bent towards alpha = 45 deg,
// then home, straight), each leg a straight line in cable space streamed as
// CABLE_SETPOINT frames a little slower than the drives can follow, and the
// robot settles at each stop. At home the host sends HOMING: from there the
// runtime knows the cables' hysteresis state (the image's homing state).
// `cycle` runs one cycle of the loop (drives, friction, runtime).
template <typename Cycle>
void run_homing_move(const model::RobotGeometry<double>& geometry, const sim::SimulatedCableDrives& drives,
                     cdcr::hal::CanBus& homing, cdcr::hal::CanBus& host, double rate_hz, Cycle&& cycle) {
  model::CableVector<double> approach_mm, home_mm;
  if (const model::Status status = model::homing_waypoints(geometry, approach_mm, home_mm);
      status != model::Status::ok) {
    throw std::runtime_error(std::string("the homing move: ") + model::to_string(status));
  }
  constexpr double kLineSpeedMmPerS = 40.0;  // the drives' 50 mm/s, with a margin
  const long settle_cycles = std::max(1L, std::lround(0.1 * rate_hz));
  const auto send_setpoints = [&](const model::CableVector<double>& cables_mm) {
    for (int s = 0; s < geometry.segment_count; ++s) {
      const auto setpoint = protocol::segment_cables_frame<protocol::CableSetpoint>(
          s, cables_mm, geometry.first_cable(s), geometry.segments[s].cables.count);
      cdcr::hal::CanFrame frame;
      if (!protocol::encode(setpoint, frame)) {
        throw std::runtime_error("the homing move: a cable length the CABLE_SETPOINT frame cannot carry");
      }
      homing.send(frame);
    }
  };
  for (const model::CableVector<double>* stop : {&approach_mm, &home_mm}) {
    const model::CableVector<double> from_mm = drives.cables_mm();
    const double longest_mm = (*stop - from_mm).cwiseAbs().maxCoeff();
    const long line_cycles = std::max(1L, static_cast<long>(std::ceil(longest_mm / kLineSpeedMmPerS * rate_hz)));
    for (long k = 1; k <= line_cycles; ++k) {
      send_setpoints(from_mm + (*stop - from_mm) * (double(k) / double(line_cycles)));
      cycle();
    }
    for (long k = 0; k < settle_cycles; ++k) cycle();
  }
  cdcr::hal::CanFrame frame;
  protocol::encode(protocol::Homing{true}, frame);
  host.send(frame);
  cycle();
}

// The closed loop following a streamed circle: the robot first goes to the
// circle's start (a single target) and settles, then a planner streams a
// TRACKING pose target every cycle around the circle once. The circle is the
// one the tip draws when every segment keeps the same bend and the bend
// direction turns: the bend that puts the nominal tip `radius_mm` off the
// axis, the targets the compensated model's poses along that motion, as a
// planner that plans with the robot's model sends them (poses the model
// says the robot takes, inside the workspace it was trained on). The
// simulated robot's true poses along the same motion are no such targets:
// near the straight robot the model's reachable poses are a thin set (the
// roll about the backbone and the tip's advance come only from combined
// bends), and at the circle's start the true pose lies 0.09 mm outside it
// (tools/bench/ik_convergence_bench.cpp measures it with a solver of its
// own). Every cycle of the stream compares the simulated robot's true tip
// with the target of that cycle: what a user of the robot sees, the
// model's error at the setpoints included.
}  // namespace

int follow_circle(const std::string& image_path, double rate_hz, double radius_mm, double speed_mm_s,
                  const SimulatedRobotChoice& robot_choice, const BusChoice& bus) {
  require_rate(rate_hz);
  if (!(radius_mm > 0) || !(radius_mm <= 100)) throw std::invalid_argument("--circle-radius must be in (0, 100] mm");
  if (!(speed_mm_s > 0) || !(speed_mm_s <= 500)) {
    throw std::invalid_argument("--circle-speed must be in (0, 500] mm/s");
  }
  SimulatedLoop loop(image_path, robot_choice, bus);
  check_bus_budget(loop.geometry.segment_count, rate_hz, true, bus);
  fw::Runtime& runtime = loop.runtime;
  const model::RobotGeometry<double>& geometry = loop.geometry;
  sim::SimulatedRobot& robot = loop.robot;
  const auto joints_at = [&](double bend_rad, double direction_rad) {
    return sim::uniform_bend_joints(geometry, bend_rad, direction_rad);
  };
  // The bend that puts the nominal tip radius_mm off the axis.
  const double bend_rad = sim::uniform_bend_for_tip_radius(geometry, radius_mm);
  const auto model_pose_at = [&](const fw::Joints& bend) {
    return (model::exp(runtime.correction().predict(bend)) * model::forward_kinematics_bend(bend, runtime.geometry()))
        .cast<double>();
  };
  const auto target_at_bend = [&](double bend, double direction_rad) {
    return model_pose_at(model::bend_from_joints(joints_at(bend, direction_rad).cast<float>()));
  };
  const auto target_at = [&](double direction_rad) { return target_at_bend(bend_rad, direction_rad); };
  model::CableVector<double> start_cables;
  model::cables_from_joints(joints_at(0.5 * bend_rad, 0.0), geometry, start_cables);
  DrivenLoop driven(loop, start_cables, rate_hz);
  cdcr::hal::FormattedCanBus& host = driven.host;
  driven.start_timer();

  long cycles = 0, poses_missing = 0, cycles_since_pose = 0;
  std::int64_t host_max_ns = 0;
  const auto cycle = [&] {
    const cdcr::hal::TimerTick tick = driven.advance_drives();
    const std::uint32_t poses = runtime.statistics().poses_published;
    const auto begin = std::chrono::steady_clock::now();
    runtime.run_cycle(tick);
    host_max_ns = std::max<std::int64_t>(
        host_max_ns,
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - begin).count());
    // A pose is due every --pose-every cycles.
    cycles_since_pose = runtime.statistics().poses_published != poses ? 0 : cycles_since_pose + 1;
    if (cycles_since_pose >= bus.rates.pose_every) ++poses_missing;
    ++cycles;
    driven.drain_host();
  };

  // Where the runtime's own compensated model puts the tip at the setpoints
  // it sent: the part of the tip's error that is the IK's.
  const auto setpoints_to_target_mm = [&](const model::Pose<double>& target) {
    return (model_pose_at(model::bend_from_joints(runtime.setpoint_joints())).position_mm - target.position_mm).norm();
  };

  // To the start as a planner moves there, along a path: the bend ramps from
  // where the drives stand to the circle's in half a second of streamed
  // targets, then half a second on the start to settle.
  // With the friction the robot first homes, and the ramp starts from home.
  if (robot_choice.hysteresis) run_homing_move(geometry, driven.drives, loop.homing_can, host, rate_hz, cycle);
  const double ramp_from = robot_choice.hysteresis ? 0.0 : 0.5;
  std::uint8_t sequence = 0;
  const long ramp_cycles = std::lround(0.5 * rate_hz);
  for (long k = 1; k <= 2 * ramp_cycles; ++k) {
    const double ramp = std::min(1.0, double(k) / double(ramp_cycles));
    send_pose_target(host, target_at_bend((ramp_from + (1.0 - ramp_from) * ramp) * bend_rad, 0.0), ++sequence, true);
    cycle();
  }
  if (const double off_mm = setpoints_to_target_mm(target_at(0.0)); !(off_mm < 1.0)) {
    const fw::IkReport& report = runtime.last_ik_report();
    throw std::runtime_error(fmt::format(
        "the circle's start was not reached: the setpoints put the model's tip {:.3f} mm off it (IK_REPORT outcome "
        "{}: {}, residual {:.3f} mm, {:.4f} rad)",
        off_mm, int(report.outcome), model::to_string(report.model_status), report.position_error_mm,
        report.orientation_error_rad));
  }

  const double step_rad = speed_mm_s / radius_mm / rate_hz;
  const long stream_cycles = std::lround(2.0 * M_PI / step_rad);
  const std::uint32_t setpoints_before = runtime.setpoints_published();
  ErrorTally error, following;
  long cycles_without_setpoints = 0;
  model::Vec3<double> center_mm = model::Vec3<double>::Zero();
  for (long k = 1; k <= stream_cycles; ++k) {
    const model::Pose<double> target = target_at(step_rad * double(k));
    const model::Vec3<double> target_mm = target.position_mm;
    center_mm += target_mm / double(stream_cycles);
    send_pose_target(host, target, ++sequence, true);
    const std::uint32_t setpoints = runtime.setpoints_published();
    cycle();
    // The first 3 cycles of the stream may still finish the settled request.
    if (k > 3 && runtime.setpoints_published() == setpoints) ++cycles_without_setpoints;
    const double error_mm = (robot.true_pose(driven.effective_cables).position_mm - target_mm).norm();
    error.add(error_mm);
    const double following_mm = setpoints_to_target_mm(target);
    following.add(following_mm);
  }
  const fw::CycleStatistics& stats = runtime.statistics();
  std::printf("state %s, fault: %s\n", fw::to_string(runtime.state()), fw::to_string(runtime.active_fault()));
  std::printf("streamed circle of pose targets: radius %.1f mm at %.1f mm/s (every segment bent %.4f rad), centre "
              "(%.1f, %.1f, %.1f) mm, %ld targets at %.0f Hz\n",
              radius_mm, speed_mm_s, bend_rad, center_mm.x(), center_mm.y(), center_mm.z(), stream_cycles, rate_hz);
  std::printf("tip vs streamed target (simulated robot): mean %.3f mm, max %.3f mm\n",
              error.sum_mm / double(stream_cycles), error.max_mm);
  std::printf("  of which following (the compensated model at the setpoints vs the target): mean %.3f mm, "
              "max %.3f mm\n",
              following.sum_mm / double(stream_cycles), following.max_mm);
  std::printf("setpoints sent in %u of %ld streamed cycles (none in %ld after the first 3); cycles %ld, poses "
              "missing %ld, overruns %u, rejected frames %u; slowest cycle on this host %.1f us\n",
              runtime.setpoints_published() - setpoints_before, stream_cycles, cycles_without_setpoints, cycles,
              poses_missing, stats.overruns, stats.rejected_frames, double(host_max_ns) * 1e-3);
  loop.print_bus_report(rate_hz, true);
  loop.finish_view();
  return 0;
}

namespace {

// A leg of the two-sided run: a via point, or a target approached from one
// side.
struct Leg {
  model::Vec3<double> position_mm;
  bool via;  // a via point: not checked
  int side;  // 0: from the +45 degree side, 1: from the -45 degree side
};

// What the random-target run measures: the runtime's pose estimate and the
// tip at its targets against the simulated robot, and the same for the
// nominal model alone, computed alongside on the host (what compensation
// gains).
struct RandomTargetTallies {
  ErrorTally estimate_error;
  long estimate_samples = 0;
  ErrorTally target_error;
  long targets_sent = 0, targets_checked = 0, targets_converged = 0;
  std::int64_t host_max_ns = 0, host_total_ns = 0;
  long host_overruns = 0;
  ErrorTally nominal_estimate_error;
  ErrorTally nominal_target_error;
  long nominal_targets_reached = 0;
  // Both sides at their commanded cables, settled: the runtime's setpoints
  // against the nominal IK's.
  ErrorTally setpoint_target_error;
  long setpoints_checked = 0;
  // With the friction: the arrivals from each side, and the first target
  // after homing, where a wrong homing state shows most.
  ErrorTally side_error[2];
  long side_checked[2] = {0, 0};
  double first_arrival_mm = 0;
};

double mean_mm(const ErrorTally& tally, long count) { return count > 0 ? tally.sum_mm / double(count) : 0.0; }

// The closed loop with random reachable targets, one per half second. With
// the friction the robot first homes, as a real one starts up, and each
// target (one per half second of --seconds, as without it) is then
// approached from two sides, each side a leg of its own: first from a via
// point where every segment's bend direction is turned +45 degrees (same
// bend), then from one turned -45 degrees. The cables across the bend plane
// reach the target once lengthening and once shortening, so the tip's error
// shows whether the runtime knows which way each cable came. Every arrival
// at a target is checked, the last one included.
class RandomTargetRun {
 public:
  RandomTargetRun(const std::string& image_path, double rate_hz, const SimulatedRobotChoice& robot_choice,
                  const BusChoice& bus)
      : loop_(image_path, robot_choice, bus),
        geometry_(loop_.geometry),
        rate_hz_(rate_hz),
        two_sided_(robot_choice.hysteresis),
        driven_(loop_, random_cables(), rate_hz),
        cycles_per_target_(std::max(1L, std::lround(0.5 * rate_hz))),
        nominal_ik_joints_(2 * geometry_.segment_count) {
    driven_.start_timer();
    for (int s = 0; s < geometry_.segment_count; ++s) {
      nominal_ik_joints_[2 * s] = 0.0;
      nominal_ik_joints_[2 * s + 1] = 0.1;
    }
  }

  void run(double seconds) {
    if (two_sided_) {
      run_homing_move(geometry_, driven_.drives, loop_.homing_can, driven_.host, rate_hz_, [this] {
        runtime().run_cycle(driven_.advance_drives());
        driven_.drain_host();
      });
      plan_two_sided_legs(std::max(1L, std::lround(seconds * rate_hz_) / cycles_per_target_));
    }
    cycles_ = two_sided_ ? long(legs_.size()) * cycles_per_target_ + 1 : std::lround(seconds * rate_hz_);
    for (long k = 0; k < cycles_; ++k) {
      const cdcr::hal::TimerTick tick = driven_.advance_drives();
      if (k % cycles_per_target_ == 0) {
        check_arrival();
        send_next_target();
      }
      run_timed_cycle(tick);
      if (runtime().has_pose()) sample_estimate();
    }
  }

  // Checks the bus budget (with a bit rate), before anything runs.
  void check_budget() const { check_bus_budget(geometry_.segment_count, rate_hz_, false, loop_.bus); }
  void print_report();

 private:
  void print_run_report() const;
  fw::Runtime& runtime() { return loop_.runtime; }
  const fw::Runtime& runtime() const { return loop_.runtime; }
  const sim::SimulatedRobot& robot() const { return loop_.robot; }

  model::JointVector<double> random_joints() {
    model::JointVector<double> joints(2 * geometry_.segment_count);
    for (int s = 0; s < geometry_.segment_count; ++s) {
      joints[2 * s] = alpha_(rng_);
      joints[2 * s + 1] = theta_(rng_);
    }
    return joints;
  }

  model::CableVector<double> random_cables() {
    model::CableVector<double> cables;
    model::cables_from_joints(random_joints(), geometry_, cables);
    return cables;
  }

  model::Vec3<double> reachable_position(const model::JointVector<double>& joints) const {
    model::CableVector<double> cables;
    model::cables_from_joints(joints, geometry_, cables);
    return robot().true_pose(cables).position_mm;
  }

  void plan_two_sided_legs(long target_count) {
    for (long t = 0; t < target_count; ++t) {
      const model::JointVector<double> joints = random_joints();
      const model::Vec3<double> target_mm = reachable_position(joints);
      for (int side = 0; side < 2; ++side) {
        model::JointVector<double> turned = joints;
        for (int s = 0; s < geometry_.segment_count; ++s) turned[2 * s] += (side == 0 ? 0.25 : -0.25) * M_PI;
        legs_.push_back({reachable_position(turned), true, side});
        legs_.push_back({target_mm, false, side});
      }
    }
  }

  // The tip where the last target was due to be reached.
  void check_arrival() {
    const Leg* previous_leg = two_sided_ && next_leg_ > 0 ? &legs_[next_leg_ - 1] : nullptr;
    if (tallies_.targets_sent == 0 || (previous_leg != nullptr && previous_leg->via)) return;
    const double error_mm = (robot().true_pose(driven_.effective_cables).position_mm - target_mm_).norm();
    tallies_.target_error.add(error_mm);
    ++tallies_.targets_checked;
    if (previous_leg != nullptr) {
      if (tallies_.targets_checked == 1) tallies_.first_arrival_mm = error_mm;
      tallies_.side_error[previous_leg->side].add(error_mm);
      ++tallies_.side_checked[previous_leg->side];
    }
    // The request spans cycles: its setpoints are checked when the next
    // target is due. (Not with the friction: the setpoints are then
    // commanded lengths, which the frictionless true pose misreads.)
    if (!two_sided_ && runtime().has_setpoints() &&
        runtime().last_ik_report().outcome == protocol::IkOutcome::converged) {
      const model::CableVector<double> setpoints_mm = runtime().setpoints_mm().cast<double>();
      tallies_.setpoint_target_error.add((robot().true_pose(setpoints_mm).position_mm - target_mm_).norm());
      ++tallies_.setpoints_checked;
    }
  }

  void send_next_target() {
    bool is_target = true;
    if (two_sided_) {
      is_target = next_leg_ < legs_.size() && !legs_[next_leg_].via;
      if (next_leg_ < legs_.size()) {
        target_mm_ = legs_[next_leg_++].position_mm;
        send_target(driven_.host, target_mm_, static_cast<std::uint8_t>(tallies_.targets_sent++));
      }
    } else {
      // Targets the real robot can reach: where it goes for random cables.
      target_mm_ = robot().true_pose(random_cables()).position_mm;
      send_target(driven_.host, target_mm_, static_cast<std::uint8_t>(tallies_.targets_sent++));
    }
    if (!is_target) return;
    const model::IkResult<double> nominal_ik = model::solve_ik_position(target_mm_, geometry_, nominal_ik_joints_);
    if (nominal_ik.converged()) {
      nominal_ik_joints_ = nominal_ik.joints;
      tallies_.nominal_target_error.add((robot().true_pose(nominal_ik.cables_mm).position_mm - target_mm_).norm());
      ++tallies_.nominal_targets_reached;
    }
  }

  void run_timed_cycle(cdcr::hal::TimerTick tick) {
    const auto begin = std::chrono::steady_clock::now();
    runtime().run_cycle(tick);
    const std::int64_t elapsed_ns =
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - begin).count();
    tallies_.host_max_ns = std::max(tallies_.host_max_ns, elapsed_ns);
    tallies_.host_total_ns += elapsed_ns;
    // Lockstep time charges the cycle nothing, so the runtime's own overrun
    // count stays zero; this is the count the host's speed would give.
    if (elapsed_ns > driven_.period_ns) ++tallies_.host_overruns;
    cdcr::hal::CanFrame frame;
    while (driven_.host.receive(frame) == cdcr::hal::CanStatus::ok) {
      protocol::IkReport report;
      if (protocol::decode(frame, report) == protocol::DecodeStatus::ok &&
          report.outcome == protocol::IkOutcome::converged) {
        ++tallies_.targets_converged;
      }
    }
  }

  void sample_estimate() {
    const model::Vec3<double> true_mm = robot().true_pose(driven_.effective_cables).position_mm;
    tallies_.estimate_error.add((true_mm - runtime().latest_pose().pose.position_mm.cast<double>()).norm());
    ++tallies_.estimate_samples;
    model::JointVector<double> nominal_joints;
    model::Pose<double> nominal_pose;
    if (model::joints_from_cables(driven_.drives.cables_mm(), geometry_, nominal_joints) == model::Status::ok &&
        model::forward_kinematics(nominal_joints, geometry_, nominal_pose) == model::Status::ok) {
      tallies_.nominal_estimate_error.add((true_mm - nominal_pose.position_mm).norm());
    }
  }

  SimulatedLoop loop_;
  const model::RobotGeometry<double>& geometry_;
  double rate_hz_;
  bool two_sided_;
  std::mt19937 rng_{7};
  std::uniform_real_distribution<double> alpha_{-M_PI, M_PI}, theta_{0.02, 0.2};
  DrivenLoop driven_;
  long cycles_per_target_;
  long cycles_ = 0;
  std::vector<Leg> legs_;
  std::size_t next_leg_ = 0;
  model::Vec3<double> target_mm_ = model::Vec3<double>::Zero();
  model::JointVector<double> nominal_ik_joints_;
  RandomTargetTallies tallies_;
};

void RandomTargetRun::print_report() {
  print_run_report();
  loop_.print_bus_report(rate_hz_, false);
  loop_.finish_view();
}

void RandomTargetRun::print_run_report() const {
  const RandomTargetTallies& t = tallies_;
  const fw::CycleStatistics& stats = runtime().statistics();
  std::printf("state %s, fault: %s\n", fw::to_string(runtime().state()), fw::to_string(runtime().active_fault()));
  std::printf("cycles %u at %.0f Hz (%.3f s simulated), overruns in simulated time %u, rejected frames %u, "
              "stale events %u\n",
              stats.cycles, rate_hz_, double(cycles_) / rate_hz_, stats.overruns, stats.rejected_frames,
              stats.stale_events);
  std::printf("cycle execution on this host: max %.1f us, mean %.1f us (period %.1f us), %ld over the period\n",
              t.host_max_ns * 1e-3, cycles_ > 0 ? double(t.host_total_ns) / double(cycles_) * 1e-3 : 0.0,
              double(driven_.period_ns) * 1e-3, t.host_overruns);
  std::printf("pose estimate vs simulated robot: mean %.3f mm, max %.3f mm over %ld cycles\n",
              mean_mm(t.estimate_error, t.estimate_samples), t.estimate_error.max_mm, t.estimate_samples);
  std::printf("targets: %ld sent, %ld converged; tip vs target after %.2f s: mean %.3f mm, max %.3f mm over %ld\n",
              t.targets_sent, t.targets_converged, double(cycles_per_target_) / rate_hz_,
              mean_mm(t.target_error, t.targets_checked), t.target_error.max_mm, t.targets_checked);
  if (two_sided_) {
    std::printf("each target approached from two sides (every bend direction turned +45 deg, then -45 deg): "
                "tip vs target mean %.3f mm (max %.3f) from the first side, %.3f mm (max %.3f) from the second\n",
                mean_mm(t.side_error[0], t.side_checked[0]), t.side_error[0].max_mm,
                mean_mm(t.side_error[1], t.side_checked[1]), t.side_error[1].max_mm);
    std::printf("first arrival after the homing move: tip vs target %.3f mm\n", t.first_arrival_mm);
  }
  std::printf("accuracy, nominal model only -> %s runtime:\n",
              runtime().latest_pose().compensated ? "compensated" : "uncompensated");
  std::printf("  pose estimate vs robot: mean %.3f -> %.3f mm, max %.3f -> %.3f mm\n",
              mean_mm(t.nominal_estimate_error, t.estimate_samples), mean_mm(t.estimate_error, t.estimate_samples),
              t.nominal_estimate_error.max_mm, t.estimate_error.max_mm);
  if (!two_sided_) {
    std::printf("  tip vs target at the commanded cables (%ld and %ld of %ld solved): mean %.3f -> %.3f mm, "
                "max %.3f -> %.3f mm\n",
                t.nominal_targets_reached, t.setpoints_checked, t.targets_sent,
                mean_mm(t.nominal_target_error, t.nominal_targets_reached),
                mean_mm(t.setpoint_target_error, t.setpoints_checked), t.nominal_target_error.max_mm,
                t.setpoint_target_error.max_mm);
  }
}

}  // namespace

int simulate(const std::string& image_path, double rate_hz, double seconds, const SimulatedRobotChoice& robot_choice,
             const BusChoice& bus) {
  require_rate(rate_hz);
  if (!(seconds > 0) || !(seconds <= 3600)) throw std::invalid_argument("--seconds must be in (0, 3600]");
  RandomTargetRun run(image_path, rate_hz, robot_choice, bus);
  run.check_budget();
  run.run(seconds);
  run.print_report();
  return 0;
}

}  // namespace cdcr::runtime_host
