#include "text_output.hpp"

#include <iterator>

#include <fmt/format.h>

namespace cdcr::cli {

std::string format_joints_table(const model::JointVector<double>& joints) {
  fmt::memory_buffer out;
  auto it = std::back_inserter(out);
  fmt::format_to(it, "joint variables (rad)\n");
  fmt::format_to(it, "  {:>7}  {:>12}  {:>12}\n", "segment", "alpha", "theta");
  for (Eigen::Index i = 0; i < joints.size() / 2; ++i) {
    fmt::format_to(it, "  {:>7}  {:>12.6f}  {:>12.6f}\n", i + 1, joints[2 * i], joints[2 * i + 1]);
  }
  return fmt::to_string(out);
}

std::string format_cables_table(const model::CableVector<double>& cables_mm,
                                const model::RobotGeometry<double>& geometry) {
  fmt::memory_buffer out;
  auto it = std::back_inserter(out);
  fmt::format_to(it, "cable lengths (mm)\n");
  fmt::format_to(it, "  {:>7}  {:>12}  {:>12}  {:>12}  {:>12}\n", "segment", "l1", "l2", "l3", "l4");
  for (int i = 0; i < geometry.segment_count; ++i) {
    fmt::format_to(it, "  {:>7}", i + 1);
    const int first = geometry.first_cable(i);
    for (int j = 0; j < geometry.segments[i].cables.count; ++j) fmt::format_to(it, "  {:>12.6f}", cables_mm[first + j]);
    // A segment of three cables has no l4.
    if (geometry.segments[i].cables.count == 3) fmt::format_to(it, "  {:>12}", "-");
    fmt::format_to(it, "\n");
  }
  return fmt::to_string(out);
}

std::string format_pose(const model::Pose<double>& pose) {
  const model::Mat4<double> m = pose.matrix();
  fmt::memory_buffer out;
  auto it = std::back_inserter(out);
  fmt::format_to(it, "tip pose in the base frame [R p; 0 0 0 1] (p in mm)\n");
  for (int row = 0; row < 4; ++row) {
    fmt::format_to(it, "  {:>10.6f}  {:>10.6f}  {:>10.6f}  {:>12.6f}\n", m(row, 0), m(row, 1), m(row, 2), m(row, 3));
  }
  return fmt::to_string(out);
}

}  // namespace cdcr::cli
