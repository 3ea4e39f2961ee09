#pragma once
// A dataset of the robot: commanded cable lengths, optionally the payload the
// end platform carried, and, when measured, the end-platform pose in the base
// frame. The CSV layout is documented in tools/dataset/format.md.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cdcr/model/se3.hpp"

namespace cdcr::dataset {

// In a motion sequence, a pause longer than this between two rows starts a new
// session: the robot may have been switched off or moved by hand, so the
// session must start with a homing move like the first one
// (tools/dataset/format.md).
inline constexpr double kSessionGapSeconds = 30.0;

struct Dataset {
  int segment_count = 0;
  // Each segment's cables, 3 or 4 (the header's columns); empty: the
  // paper's four each.
  std::vector<int> segment_cables;
  Eigen::MatrixXd cables_mm;                   // samples x cables, columns l1_1, l1_2, ..., segment by segment
  Eigen::VectorXd payload_kg;                  // one per sample when has_payload: finite, not negative
  bool has_payload = false;
  std::vector<model::Pose<double>> poses;      // one per sample when has_poses
  bool has_poses = false;
  // A motion sequence (the file's first column is t_s): the time of every
  // row, strictly increasing within a session, and the first row of every
  // session (each starts after a homing move; session_starts[0] == 0).
  // Without a time column the rows are independent samples.
  Eigen::VectorXd time_s;
  std::vector<int> session_starts;
  bool has_time = false;
  // Whether every session began with the homing move, as the format asks;
  // false for a recording without it (cdcr train --no-homing): each session
  // starts at power-up, the cables' state unknown, as the board's does.
  bool sessions_homed = true;
  std::uint64_t content_hash = 0;              // 64-bit FNV-1a of the file's bytes

  int sample_count() const { return static_cast<int>(cables_mm.rows()); }
  int cables_of(int segment) const {
    return segment_cables.empty() ? 4 : segment_cables[static_cast<std::size_t>(segment)];
  }
  int cable_count() const {
    int count = 0;
    for (int i = 0; i < segment_count; ++i) count += cables_of(i);
    return count;
  }
};

}  // namespace cdcr::dataset
