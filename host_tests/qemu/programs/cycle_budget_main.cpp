// The cycle budget on the board: thousands of consecutive Runtime::run_cycle
// calls, each counted in instructions (QEMU -icount, as cycle_bench_main),
// over a workload that mixes everything a cycle can meet:
//   forward-only cycles; position and pose targets anywhere in the paper's
//   workspace, and pose targets over the full design range; unreachable
//   targets; a streamed circle (a TRACKING target every cycle, 100 mm/s);
//   targets superseded every few cycles; a drive falling silent (FAULT) and
//   coming back.
// The drives are ideal: each cycle they report the last setpoints they got.
// Targets are made on the board from random joints with the runtime's own
// model (not counted). Prints `worst cycle: N instructions over C cycles`
// and the latency figures in cycles, and fails when a cycle exceeds the
// board's budget (80,000 instructions on the Cortex-M7, 120,000 on the
// Cortex-M4F).
//
// Linked with an image that has a hysteresis block
// (cdcr_qemu_cycle_budget_hysteresis, kExpectHysteresisBlock), the runtime
// starts with the state unknown (its r95 widening runs), the drives' moves
// make it known, and the program also reports what the hysteresis itself
// costs: the tracking of a cable set and the widening's Jacobian, at most,
// in instructions.
//
// Linked with a payload model whose image has a compliance block
// (cdcr_qemu_cycle_budget_compliance, kExpectComplianceBlock), the runtime
// sags the nominal pose under the payload in every cycle, and the program
// reports what the sag costs: the forward path's sagged bends and the IK
// correction's commanded bends, at most, in instructions. After the
// measured cycles it checks the board's sagged pose at the golden cables
// against the host's.

#include <algorithm>
#include <cmath>

#include <cdcr/cortexm/semihosting.hpp>
#include <cdcr/firmware/ik_settings.hpp>
#include <cdcr/firmware/runtime.hpp>

#include "board.hpp"
#include "cycle_tally.hpp"
#include "golden_check.hpp"
#include "instruction_count.hpp"
#include "program_expectation.hpp"
#include "workload.hpp"

namespace {

namespace console = cdcr::cortexm;
using namespace cdcr::qemu_programs;  // the workload, and its model, firmware and protocol

cdcr::boards::mps2::Board board;
firmware::Runtime runtime(board.hal(), cdcr::boards::mps2::golden_geometry());
firmware::Correction correction;

cdcr::boards::mps2::InstructionCounter counter{board.timer};

// The same workload on every run and both boards (workload.hpp).
cdcr::qemu_programs::Random random_numbers{0x2545F491u};
cdcr::qemu_programs::IdealDrives drives;
int& segments = drives.segments;
int& silent_segment = drives.silent_segment;

void exchange_with_drives() { drives.exchange(board.can); }

void deliver_target(const model::Pose<float>& target, protocol::TargetMode mode, bool tracking,
                    std::uint8_t sequence, bool refuse_extrapolating = false) {
  cdcr::qemu_programs::deliver_target(board.can, target, mode, tracking, sequence, refuse_extrapolating);
}

model::Pose<float> compensated_tip(const model::JointVector<float>& joints) {
  return cdcr::qemu_programs::compensated_tip(correction, runtime.geometry(), joints);
}

model::Pose<float> reachable_target(float theta_max_rad) {
  return cdcr::qemu_programs::reachable_target(random_numbers, correction, runtime.geometry(), theta_max_rad);
}

// Latencies in cycles, per kind of request.
constexpr const char* full_range_name = "full_range_pose";
constexpr int kMaxSamples = 800;
struct Latencies {
  const char* name;
  std::uint16_t cycles[kMaxSamples];
  int count = 0;
  int converged = 0;
  int converged_within_200 = 0;
  void add(int spent, bool ok) {
    if (count < kMaxSamples) cycles[count++] = static_cast<std::uint16_t>(spent);
    converged += ok ? 1 : 0;
    converged_within_200 += ok && spent <= 200 ? 1 : 0;
  }
  void report() {
    if (count == 0) return;
    std::sort(cycles, cycles + count);
    console::console_write("latency ");
    console::console_write(name);
    console::console_write(": n ");
    console::console_write_int(count);
    console::console_write(" converged ");
    console::console_write_int(converged);
    if (name == full_range_name) {
      console::console_write(" (within 200 cycles ");
      console::console_write_int(converged_within_200);
      console::console_write(")");
    }
    console::console_write(" p50 ");
    console::console_write_int(cycles[count / 2]);
    console::console_write(" p99 ");
    console::console_write_int(cycles[std::min(count - 1, (count * 99) / 100)]);
    console::console_write(" max ");
    console::console_write_int(cycles[count - 1]);
    console::console_write(" cycles\n");
  }
};

// Targets that refuse extrapolation, all made inside the training data's
// range or all beyond it, and what became of them.
struct RefusingTargets {
  std::int32_t sent = 0;
  std::int32_t converged = 0;
  std::int32_t refused = 0;
};

// What the workload's steps share: the counted cycles' tallies, the
// sequence of the next target, the latencies per kind of request, and
// what became of the targets that refuse extrapolation and of the silent
// drive.
struct Workload {
  CycleTally tally;
  // Instructions of a GP mean point (report_unit_costs), and the most any
  // cycle spent beyond what its units account for.
  std::uint32_t mean_point_instructions = 0;
  std::int32_t worst_unaccounted = 0;
  std::uint8_t next_sequence = 0;
  Latencies paper_pose{"paper_pose"};
  Latencies paper_position{"paper_position"};
  Latencies full_range_pose{full_range_name};
  Latencies near_straight_pose{"near_straight_pose"};
  Latencies streamed{"streamed_setpoint_lag"};
  // [0] made inside the training data's range, [1] beyond it.
  RefusingTargets refusing[2];
  // The silent drive faulted the runtime, and its return recovered it.
  bool faulted = false;
  bool recovered = false;

  // One counted cycle with the drives' exchange around it.
  void cycle();
  // A target, then cycles until its request ends; returns the cycles spent.
  int solve(const model::Pose<float>& target, protocol::TargetMode mode, Latencies* latencies,
            bool refuse_extrapolating = false);
};

void Workload::cycle() {
  exchange_with_drives();
  const std::uint32_t instructions = tally.run_counted(counter, board, runtime);
  const std::int32_t accounted = std::int32_t(mean_point_instructions * (correction.training_points() +
                                                                         runtime.ik_units_last_cycle()));
  worst_unaccounted = std::max(worst_unaccounted, std::int32_t(instructions) - accounted);
  // The first few over the budget, with what the cycle did: enough to tell
  // which work is under-charged.
  if (tally.among_first_over_budget(5)) {
    tally.print_over_budget(runtime, [] {});
    console::console_write(runtime.ik_running() ? ", request running\n" : ", no request running\n");
  }
}

int Workload::solve(const model::Pose<float>& target, protocol::TargetMode mode, Latencies* latencies,
                    bool refuse_extrapolating) {
  const std::uint8_t sequence = next_sequence++;
  deliver_target(target, mode, false, sequence, refuse_extrapolating);
  int spent = 0;
  do {
    cycle();
    ++spent;
  } while (runtime.ik_running() && spent < firmware::kMaxIkCycles + 2);
  const bool ok = runtime.last_ik_report().sequence == sequence &&
                  runtime.last_ik_report().outcome == protocol::IkOutcome::converged;
  if (latencies != nullptr) latencies->add(spent, ok);
  return spent;
}

// What each kind of IK work costs on this core, in instructions: the
// figures behind the work-unit costs the board's architecture file states
// (model/arch/<arch>). A training point of the mean is the unit; returns
// its instructions.
firmware::Solver probe_solver;
firmware::SolverCorrection probe_correction(correction);

std::uint32_t report_unit_costs(const model::ImageView& image) {
  const std::uint32_t points = correction.training_points();
  model::JointVector<float> bend = model::JointVector<float>::Zero(2 * segments);
  for (int s = 0; s < segments; ++s) bend[2 * s] = 0.1f;
  firmware::Correction::Evaluation evaluation;
  probe_correction.begin_evaluation(bend, evaluation, false);
  const std::uint32_t mean = counter.instructions([&] { probe_correction.continue_evaluation(evaluation, points); });
  probe_correction.begin_evaluation(bend, evaluation, true);
  const std::uint32_t gradient =
      counter.instructions([&] { probe_correction.continue_evaluation(evaluation, points * firmware::Correction::kGradientPointUnits); });
  // Each run(kProbeBudget) call of a solver charged these costs does one
  // step, told apart by the units it returns.
  constexpr std::uint32_t kProbeJacobian = 100'000, kProbeStep = 99'999, kProbeOuter = 99'998;
  constexpr std::uint32_t kProbeBudget = 100'000;
  model::IkSolverOptions<float> options;
  probe_solver.configure(runtime.geometry(), probe_correction, options,
                         model::IkWorkCosts{kProbeJacobian, kProbeStep, kProbeOuter});
  std::uint32_t start_max = 0;
  struct Step {
    std::uint32_t units, max = 0, count = 0;
    std::uint64_t total = 0;
  } steps[3] = {{kProbeJacobian}, {kProbeStep}, {kProbeOuter}};
  // The same targets again with the preference a target that refuses
  // extrapolation has: its steps' own cost.
  Step preferred_step{kProbeStep};
  model::Pose<float> targets[16];
  for (int t = 0; t < 16; ++t) targets[t] = reachable_target(t % 2 ? 0.2f : 1.5f);
  for (int pass = 0; pass < 32; ++pass) {
    const int t = pass % 16;
    if (pass == 16) probe_solver.set_preference(firmware::ik_preference(runtime.geometry(), &image));
    Step* measured = pass < 16 ? steps : &preferred_step;
    const int kinds = pass < 16 ? 3 : 1;
    const model::Pose<float>& target = targets[t];
    model::JointVector<float> initial(2 * segments);
    for (int s = 0; s < segments; ++s) {
      initial[2 * s] = 0.0f;
      initial[2 * s + 1] = 0.1f;
    }
    const model::IkTargetKind kind = t % 4 < 2 ? model::IkTargetKind::pose : model::IkTargetKind::position;
    start_max = std::max(start_max, counter.instructions([&] { probe_solver.start(target, kind, initial); }));
    for (int call = 0; call < 4000 && probe_solver.state() == model::IkSolveState::running; ++call) {
      std::uint32_t units = 0;
      const std::uint32_t instructions = counter.instructions([&] { units = probe_solver.run(kProbeBudget); });
      for (int k = 0; k < kinds; ++k) {
        Step& step = measured[k];
        if (units != step.units) continue;
        step.max = std::max(step.max, instructions);
        step.total += instructions;
        ++step.count;
      }
    }
  }
  const auto write = [](const char* label, std::uint32_t value) {
    console::console_write(label);
    console::console_write_int(static_cast<std::int32_t>(value));
  };
  const std::uint32_t mean_point = (mean + points / 2) / points;
  write("unit costs (instructions): mean point ", mean_point);
  write(", gradient point ", (gradient + points / 2) / points);
  const char* const names[3] = {"; nominal jacobian mean ", "; nominal step mean ", "; outer step mean "};
  for (int i = 0; i < 3; ++i) {
    write(names[i], steps[i].count ? std::uint32_t(steps[i].total / steps[i].count) : 0);
    write(" max ", steps[i].max);
  }
  write("; nominal step with the preference mean ",
        preferred_step.count ? std::uint32_t(preferred_step.total / preferred_step.count) : 0);
  write(" max ", preferred_step.max);
  write("; start max ", start_max);
  // A request's end: the setpoints (cable lengths of the joints and their
  // frames) and the report's frame, as the runtime makes them.
  model::JointVector<float> joints(2 * segments);
  for (int s = 0; s < segments; ++s) {
    joints[2 * s] = 0.3f * float(s);
    joints[2 * s + 1] = 0.15f;
  }
  model::CableVector<float, firmware::kMaxSegments> cables;
  cdcr::hal::CanFrame frames[firmware::kMaxSegments];
  const firmware::Geometry& geometry = runtime.geometry();
  const std::uint32_t setpoints = counter.instructions([&] {
    model::cables_from_joints(joints, geometry, cables);
    for (int s = 0; s < segments; ++s) {
      protocol::encode(protocol::segment_cables_frame<protocol::CableSetpoint>(s, cables, geometry.first_cable(s),
                                                                               geometry.segments[s].cables.count),
                       frames[s]);
    }
  });
  // The residuals are read through volatile: the codec inlines into this
  // file, and constants would let the compiler encode the frame while
  // compiling it, where the runtime encodes a solver's results.
  volatile double position_residual_mm = 0.001;
  volatile double orientation_residual_rad = 0.0001;
  const std::uint32_t report = counter.instructions([&] {
    protocol::encode(protocol::IkReport{1, protocol::IkOutcome::converged, 12, 30, position_residual_mm,
                                        orientation_residual_rad},
                     frames[0]);
  });
  write("; setpoints ", setpoints);
  write("; report ", report);
  console::console_write("\n");
  return mean_point;
}

firmware::HysteresisTracker probe_tracker;
firmware::RobotModel probe_model;

// The hysteresis' work in a cycle, measured on a tracker of its own bound to
// the same image: a cable set's update and effective lengths (the state
// unknown, then known), and the widening's nominal Jacobian.
void report_hysteresis_costs(const model::ImageView& image) {
  probe_model.geometry = runtime.geometry();
  probe_model.image = image;
  probe_model.compensated = true;
  probe_tracker.bind(probe_model);
  firmware::Cables cases[4];
  for (int c = 0; c < 4; ++c) {
    cases[c].resize(4 * segments);
    for (int i = 0; i < 4 * segments; ++i) cases[c][i] = float(cdcr::qemu_golden::kCablesMm[c][i]);
  }
  std::uint32_t track_max = 0, widen_max = 0;
  for (int round = 0; round < 12; ++round) {
    const firmware::Cables& cables = cases[round % 4];
    const bool unknown = !probe_tracker.known();
    track_max = std::max(track_max, counter.instructions([&] { probe_tracker.track(cables); }));
    if (unknown) {
      firmware::PoseEstimate estimate;
      runtime.estimate_pose(cables, estimate);
      widen_max = std::max(widen_max, counter.instructions([&] { probe_tracker.begin_variance(probe_model, estimate); }));
    }
  }
  console::console_write("hysteresis costs (instructions): ");
  console::console_write_int(probe_tracker.hysteresis_model().cables);
  console::console_write(" cables x ");
  console::console_write_int(probe_tracker.hysteresis_model().operators);
  console::console_write(" operators; track max ");
  console::console_write_int(static_cast<std::int32_t>(track_max));
  console::console_write(", widening max ");
  console::console_write_int(static_cast<std::int32_t>(widen_max));
  console::console_write("; charged ");
  console::console_write_int(static_cast<std::int32_t>(firmware::hysteresis_units(runtime.hysteresis())));
  console::console_write(" units a cycle\n");
}

// The sag's work, at the golden cases' bends and the image's default
// payload: the forward path's sagged bends and the inverse the IK's
// correction runs per evaluation, as the firmware compiles them.
void report_compliance_costs() {
  const firmware::Compliance& compliance = runtime.compliance();
  const float payload_kg = runtime.payload_kg();
  std::uint32_t sag_max = 0, inverse_max = 0;
  for (int c = 0; c < 8; ++c) {
    firmware::Joints joints(2 * segments);
    for (int k = 0; k < 2 * segments; ++k) joints[k] = cdcr::qemu_golden::kJoints[c][k];
    const firmware::Joints bend = model::bend_from_joints(joints);
    firmware::Joints sagged;
    sag_max = std::max(sag_max, counter.instructions([&] {
      sagged = firmware::sagged_bends_of(compliance, runtime.geometry(), payload_kg, bend);
    }));
    firmware::Joints back;
    inverse_max = std::max(inverse_max, counter.instructions([&] {
      back = firmware::commanded_bends_of(compliance, runtime.geometry(), payload_kg, sagged);
    }));
  }
  console::console_write("compliance costs (instructions): sag max ");
  console::console_write_int(static_cast<std::int32_t>(sag_max));
  console::console_write(", inverse max ");
  console::console_write_int(static_cast<std::int32_t>(inverse_max));
  console::console_write("; charged ");
  console::console_write_int(static_cast<std::int32_t>(firmware::kComplianceUnits));
  console::console_write(" units a cycle\n");
}

// The board's compensated pose at the golden cables, its nominal pose
// sagged under the image's default payload, against the host's double one
// (make_qemu_golden), within the replay's float32 fidelity targets.
bool sagged_pose_matches_host() {
  constexpr double kPositionToleranceMm = 0.01;
  constexpr double kOrientationToleranceDeg = 0.001;
  if (runtime.payload_kg() != float(cdcr::qemu_golden::kPayloadKg)) {
    console::console_write("FAIL: the runtime's payload is not the image's default the host used\n");
    return false;
  }
  cdcr::boards::mps2::PoseDeviation largest;
  for (int c = 0; c < cdcr::qemu_golden::kCases; ++c) {
    firmware::Cables cables_mm(4 * segments);
    for (int i = 0; i < 4 * segments; ++i) cables_mm[i] = float(cdcr::qemu_golden::kCablesMm[c][i]);
    firmware::PoseEstimate estimate;
    if (runtime.estimate_pose(cables_mm, estimate) != model::Status::ok) {
      console::console_write("FAIL: no sagged pose at a golden case\n");
      return false;
    }
    const cdcr::boards::mps2::PoseDeviation d = cdcr::boards::mps2::deviation(
        estimate.pose, cdcr::boards::mps2::golden_pose<double>(cdcr::qemu_golden::kSaggedPositionMm[c],
                                                               cdcr::qemu_golden::kSaggedRotation[c]));
    largest.position_mm = std::max(largest.position_mm, d.position_mm);
    largest.orientation_deg = std::max(largest.orientation_deg, d.orientation_deg);
  }
  console::console_write("sagged pose, largest deviation from the host: ");
  console::console_write_fixed(largest.position_mm, 6);
  console::console_write(" mm, ");
  console::console_write_fixed(largest.orientation_deg, 6);
  console::console_write(" deg\n");
  if (largest.position_mm <= kPositionToleranceMm && largest.orientation_deg <= kOrientationToleranceDeg) return true;
  console::console_write("FAIL: the sagged pose beyond the float32 fidelity target\n");
  return false;
}

// The steps of main are inlined into it, where their code was before it was
// split into them, so that the compiler weighs this file as it did. The
// program's copy of the IK solver (probe_solver's, which the program links
// for the runtime too) depends on it: with the steps as functions of their
// own, a clone of forward_kinematics_bend for the runtime's geometry made
// the solver's evaluate_pose small enough to inline, and the outer step's
// count rose 1 % on the Cortex-M7.
#define WORKLOAD_STEP inline __attribute__((always_inline))

// The start: the runtime in RUN with the image bound, the counter
// calibrated, what the model is and what its work costs, and the image's
// blocks (hysteresis, compliance) as the program was linked to expect.
WORKLOAD_STEP bool start(Workload& workload) {
  model::ImageView image{};
  if (!cdcr::qemu_programs::start_counting(board, runtime, correction, image)) return false;
  segments = runtime.geometry().segment_count;
  counter.calibrate();
  console::console_write("model: ");
  console::console_write_int(static_cast<std::int32_t>(image.training_points));
  console::console_write(" training points; IK work per cycle ");
  console::console_write_int(static_cast<std::int32_t>(runtime.ik_units_per_cycle()));
  console::console_write(" units\n");
  workload.mean_point_instructions = report_unit_costs(image);
  const bool with_hysteresis = cdcr::qemu_programs::kExpectHysteresisBlock;
  if (runtime.hysteresis().active() != with_hysteresis) {
    console::console_write(with_hysteresis ? "FAIL: the image's hysteresis block is not tracked\n"
                                           : "FAIL: a hysteresis block where the image has none\n");
    return false;
  }
  if (with_hysteresis) {
    if (runtime.hysteresis().known()) {
      console::console_write("FAIL: the hysteresis state is known at power-up\n");
      return false;
    }
    report_hysteresis_costs(image);
  }
  const bool with_compliance = cdcr::qemu_programs::kExpectComplianceBlock;
  if (runtime.compliance().empty() == with_compliance) {
    console::console_write(with_compliance ? "FAIL: the image's compliance block is not bound\n"
                                           : "FAIL: a compliance block where the image has none\n");
    return false;
  }
  if (with_compliance) report_compliance_costs();
  const firmware::Geometry& geometry = runtime.geometry();
  if ((geometry.cable_count() == 3 * segments) != cdcr::qemu_programs::kExpectThreeCables) {
    console::console_write(cdcr::qemu_programs::kExpectThreeCables ? "FAIL: the image's segments have not three cables\n"
                                                                   : "FAIL: an image of three cables a segment\n");
    return false;
  }
  return true;
}

// The drives start where golden case 0 has them (the golden cases are the
// four-cable robot's; a three-cable robot starts at a bend of its own);
// forward-only cycles.
WORKLOAD_STEP void forward_only_cycles(Workload& workload) {
  const firmware::Geometry& geometry = runtime.geometry();
  firmware::Cables start(geometry.cable_count());
  if (geometry.paper_cables()) {
    for (int i = 0; i < start.size(); ++i) start[i] = float(cdcr::qemu_golden::kCablesMm[0][i]);
  } else {
    model::JointVector<float> joints(2 * segments);
    for (int s = 0; s < segments; ++s) {
      joints[2 * s] = 0.4f * float(s);
      joints[2 * s + 1] = 0.12f;
    }
    model::cables_from_joints(joints, geometry, start);
  }
  for (int s = 0; s < segments; ++s) {
    const protocol::CableFeedback lengths = protocol::segment_cables_frame<protocol::CableFeedback>(
        s, start, geometry.first_cable(s), geometry.segments[s].cables.count);
    for (int k = 0; k < 4; ++k) drives.lengths_mm[s][k] = float(lengths.lengths_mm[k]);
  }
  for (int i = 0; i < 100; ++i) workload.cycle();
}

// Targets anywhere in the paper's workspace, pose and position, with an
// unreachable one every eighth.
WORKLOAD_STEP void paper_workspace_targets(Workload& workload) {
  for (int t = 0; t < 240; ++t) {
    if (t % 8 == 7) {
      model::Pose<float> far;
      far.position_mm = model::Vec3<float>(900.0f, 0.0f, 50.0f);
      workload.solve(far, protocol::TargetMode::position, nullptr);
    } else if (t % 3 == 0) {
      workload.solve(reachable_target(0.2f), protocol::TargetMode::position, &workload.paper_position);
    } else {
      workload.solve(reachable_target(0.2f), protocol::TargetMode::pose, &workload.paper_pose);
    }
  }
}

// Pose targets that refuse extrapolation, inside the training data's
// range and beyond it (bends to 0.45 rad): the solution's check (range,
// then the variance in IK's slices) within the same budget.
WORKLOAD_STEP void targets_refusing_extrapolation(Workload& workload) {
  for (int t = 0; t < 40; ++t) {
    const int beyond = t % 2;
    workload.solve(reachable_target(beyond ? 0.45f : 0.15f), protocol::TargetMode::pose, nullptr, true);
    RefusingTargets& refusing = workload.refusing[beyond];
    ++refusing.sent;
    const protocol::IkOutcome outcome = runtime.last_ik_report().outcome;
    refusing.converged += outcome == protocol::IkOutcome::converged ? 1 : 0;
    refusing.refused += outcome == protocol::IkOutcome::refused_extrapolating ? 1 : 0;
  }
}

// The streamed circle's centre: at the height where the robot, every
// segment bent the same way, reaches 120 mm off its axis (found by
// bisection), 10 mm off the axis (points there need S-shaped bends of
// about the same size).
WORKLOAD_STEP model::Vec3<float> streamed_circle_center() {
  float low = 0.0f, high = 0.5f;
  model::Vec3<float> rim;
  for (int i = 0; i < 40; ++i) {
    model::JointVector<float> equal_bend(2 * segments);
    for (int s = 0; s < segments; ++s) {
      equal_bend[2 * s] = 0.0f;
      equal_bend[2 * s + 1] = 0.5f * (low + high);
    }
    rim = model::forward_kinematics_bend(model::bend_from_joints(equal_bend), runtime.geometry()).position_mm;
    (rim.head<2>().norm() < 120.0f ? low : high) = 0.5f * (low + high);
  }
  return model::Vec3<float>(10.0f, 0.0f, rim.z());
}

// A streamed circle, 40 mm radius at 100 mm/s: a TRACKING position target
// every cycle, inside the workspace. First the robot goes to the circle's
// start.
WORKLOAD_STEP void streamed_circle(Workload& workload) {
  const model::Vec3<float> center = streamed_circle_center();
  const auto on_circle = [&](int step) {
    const float angle = 2.5e-3f * float(step);  // 100 mm/s at 1 kHz on a 40 mm radius
    model::Pose<float> p;
    p.position_mm = center + model::Vec3<float>(40.0f * std::cos(angle), 40.0f * std::sin(angle), 0.0f);
    return p;
  };
  workload.solve(on_circle(0), protocol::TargetMode::position, nullptr);
  // How far the drives lag: the compensated model's tip at the setpoints
  // they hold, against the target of this cycle, in cycles of path (0.1 mm
  // each at 100 mm/s and 1 kHz).
  constexpr float kPathPerCycleMm = 0.1f;
  model::Vec3<float> held_tip = compensated_tip(runtime.setpoint_joints()).position_mm;
  for (int step = 1; step <= 800; ++step) {
    deliver_target(on_circle(step), protocol::TargetMode::position, true, workload.next_sequence++);
    const std::uint32_t before = runtime.setpoints_published();
    workload.cycle();
    if (runtime.setpoints_published() != before) held_tip = compensated_tip(runtime.setpoint_joints()).position_mm;
    const float lag = (held_tip - on_circle(step).position_mm).norm() / kPathPerCycleMm;
    if (step > 20) workload.streamed.add(static_cast<int>(std::ceil(lag)), true);
  }
  while (runtime.ik_running()) workload.cycle();
}

// Superseding targets: a new one every 3 cycles.
WORKLOAD_STEP void superseding_targets(Workload& workload) {
  for (int t = 0; t < 40; ++t) {
    deliver_target(reachable_target(0.2f), t % 2 ? protocol::TargetMode::pose : protocol::TargetMode::position, false,
                   workload.next_sequence++);
    for (int i = 0; i < 3; ++i) workload.cycle();
  }
}

// A drive falls silent while a request runs, and comes back.
WORKLOAD_STEP void silent_drive(Workload& workload) {
  deliver_target(reachable_target(0.2f), protocol::TargetMode::pose, false, workload.next_sequence++);
  workload.cycle();
  silent_segment = segments - 1;
  for (int i = 0; i < 30; ++i) workload.cycle();
  workload.faulted = runtime.state() == firmware::RuntimeState::fault;
  silent_segment = -1;
  for (int i = 0; i < 10; ++i) workload.cycle();
  workload.recovered = runtime.state() == firmware::RuntimeState::run;
  while (runtime.ik_running()) workload.cycle();
}

// Pose targets over the full design range, each from a straight start.
WORKLOAD_STEP void full_range_targets(Workload& workload) {
  for (int t = 0; t < 100; ++t) {
    const model::JointVector<float> straight = model::JointVector<float>::Zero(2 * segments);
    const model::Pose<float> straight_target = model::forward_kinematics_bend(straight, runtime.geometry());
    workload.solve(straight_target, protocol::TargetMode::position, nullptr);
    workload.solve(reachable_target(0.97f * 1.5707963f), protocol::TargetMode::pose, &workload.full_range_pose);
  }
}

// Pose targets near the straight robot (every segment bent at most 0.06
// rad), where the roll about the backbone is weakly actuated, each from
// the last one's setpoints.
WORKLOAD_STEP void near_straight_targets(Workload& workload) {
  for (int t = 0; t < 60; ++t) {
    workload.solve(reachable_target(0.06f), protocol::TargetMode::pose, &workload.near_straight_pose);
  }
}

// The latencies, the targets refusing extrapolation and the cycles' overhead.
WORKLOAD_STEP void report_workload(Workload& workload) {
  workload.paper_pose.report();
  workload.paper_position.report();
  workload.full_range_pose.report();
  workload.near_straight_pose.report();
  workload.streamed.report();
  for (int beyond = 0; beyond < 2; ++beyond) {
    const RefusingTargets& refusing = workload.refusing[beyond];
    console::console_write(beyond ? "targets refusing extrapolation, made beyond the data: n "
                                  : "targets refusing extrapolation, made inside the data: n ");
    console::console_write_int(refusing.sent);
    console::console_write(" converged ");
    console::console_write_int(refusing.converged);
    console::console_write(" refused ");
    console::console_write_int(refusing.refused);
    console::console_write("\n");
  }
  console::console_write("cycle overhead (beyond the units spent): at most ");
  console::console_write_int(workload.worst_unaccounted);
  console::console_write(" instructions\n");
}

// What the runtime did with the workload: every cycle within budget with
// its pose, the silent drive's fault and recovery, the targets' outcomes.
WORKLOAD_STEP bool workload_passes(const Workload& workload) {
  bool ok = workload.tally.report();
  if (!workload.faulted || !workload.recovered) {
    console::console_write("FAIL: the silent drive did not fault the runtime, or its return did not recover it\n");
    ok = false;
  }
  // A target made inside the data has a solution there, which the search
  // should find: with the preference for the middle of the data none of the
  // 20 is refused on either board (1 without it; with a single retry from
  // the straight start, 4 on the M7 and 9 on the M4F were). The payload
  // model with a compliance block, on which IK converges on fewer than half
  // the targets within a request's cycles, still has one refused on the
  // M4F. One made beyond it may have one too (the robot is redundant), but
  // not all of them do.
  if (workload.refusing[0].refused > (cdcr::qemu_programs::kExpectComplianceBlock ? 1 : 0)) {
    console::console_write("FAIL: targets made inside the data were refused as extrapolating\n");
    ok = false;
  }
  // Reachable pose targets in the paper's workspace and near the straight
  // robot all converge (not with the payload model and its sag: see above).
  const Latencies& paper = workload.paper_pose;
  const Latencies& near_straight = workload.near_straight_pose;
  if (!cdcr::qemu_programs::kExpectComplianceBlock &&
      (paper.converged < paper.count || near_straight.converged < near_straight.count)) {
    console::console_write("FAIL: reachable pose targets did not converge\n");
    ok = false;
  }
  if (workload.refusing[1].refused == 0) {
    console::console_write("FAIL: no target made beyond the data was refused\n");
    ok = false;
  }
  return ok;
}

// What the image's blocks and the run's length must be at the end.
WORKLOAD_STEP bool run_passes(const Workload& workload) {
  bool ok = true;
  if (cdcr::qemu_programs::kExpectHysteresisBlock && !runtime.hysteresis().known()) {
    console::console_write("FAIL: the drives' moves did not make the hysteresis state known\n");
    ok = false;
  }
  if (cdcr::qemu_programs::kExpectComplianceBlock && !sagged_pose_matches_host()) ok = false;
  if (workload.tally.cycles_run() < 2000) {
    console::console_write("FAIL: fewer than 2,000 cycles\n");
    ok = false;
  }
  return ok;
}

}  // namespace

int main() {
  // Static: the latencies' samples (8 KiB) would take most of the 12 KiB
  // stack.
  static Workload workload;
  if (!start(workload)) return 1;
  forward_only_cycles(workload);
  paper_workspace_targets(workload);
  targets_refusing_extrapolation(workload);
  streamed_circle(workload);
  superseding_targets(workload);
  silent_drive(workload);
  full_range_targets(workload);
  near_straight_targets(workload);
  report_workload(workload);
  const bool workload_ok = workload_passes(workload);
  const bool ok = run_passes(workload) && workload_ok;
  console::console_write(ok ? "PASS\n" : "FAIL\n");
  return ok ? 0 : 1;
}
