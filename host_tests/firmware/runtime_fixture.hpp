#pragma once
// A runtime on the simulated platform, with a small synthetic model image.

#include <cstdint>
#include <vector>

#include <cdcr/firmware/runtime.hpp>
#include <cdcr/sim/lockstep_timer.hpp>
#include <cdcr/sim/memory_model_storage.hpp>
#include <cdcr/sim/virtual_can.hpp>

#include "export/image_writer.hpp"
#include "recording_console.hpp"
#include "sim/simulated_drives.hpp"
#include "synthetic_trained_model.hpp"

namespace cdcr::test_support {

// Corrections a few tenths of a millimetre and milliradians: the size of the
// errors a trained model corrects, so IK behaves as on the robot.
inline training::TrainedModel small_correction_model(int training_points = 5) {
  SyntheticModelOptions options;
  options.training_points = training_points;
  training::TrainedModel m = synthetic_trained_model(options);
  for (int k = 0; k < 6; ++k) {
    m.output_mean[k] *= k < 3 ? 0.1 : 0.001;
    m.output_scale[k] *= k < 3 ? 0.1 : 0.001;
  }
  return m;
}

inline std::vector<std::uint8_t> small_image() { return exporting::write_image(small_correction_model()); }

// A model large enough that a compensated IK request spans several cycles.
inline std::vector<std::uint8_t> multi_cycle_image() { return exporting::write_image(small_correction_model(600)); }

struct SimulatedPlatform {
  sim::VirtualCanBus bus;
  sim::LockstepClock clock;
  sim::LockstepTimer timer{clock};
  sim::MemoryModelStorage storage;
  test_support::RecordingConsole console;
  hal::Hal hal{clock, timer, bus.node(0), storage, console};
  hal::CanBus& drives_node = bus.node(1);
  hal::CanBus& host_node = bus.node(2);

  explicit SimulatedPlatform(const std::vector<std::uint8_t>& image) {
    storage.assign(image);
    timer.start(1'000'000);
  }
};

// Cable lengths of a gently bent robot with the image's geometry.
inline model::CableVector<double, firmware::kMaxSegments> bent_cables(const firmware::Geometry& geometry,
                                                                    double theta_rad = 0.15) {
  model::RobotGeometry<double> g;
  g.segment_count = geometry.segment_count;
  for (int s = 0; s < g.segment_count; ++s) {
    g.segments[s] = {double(geometry.segments[s].backbone_length_mm), double(geometry.segments[s].anchor_radius_mm),
                     double(geometry.segments[s].theta_max_rad), geometry.segments[s].cables.cast<double>()};
  }
  model::JointVector<double> joints(2 * g.segment_count);
  for (int s = 0; s < g.segment_count; ++s) {
    joints[2 * s] = 0.7 * (s + 1);
    joints[2 * s + 1] = theta_rad;
  }
  model::CableVector<double> cables;
  model::cables_from_joints(joints, g, cables);
  return cables;
}

}  // namespace cdcr::test_support
