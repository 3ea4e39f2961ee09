#pragma once
// Motion-capture import: rigid-body poses from a Qualisys Track Manager (QTM)
// 6DOF TSV export, and the end-platform pose in the base frame of eq. (21),
//
//   T_end_in_base = (T_base_in_camera)^-1 * T_end_in_camera,
//
// paired row by row with the commanded cable lengths into a dataset.
//
// Accepted layout (tab-separated, LF or CRLF):
//   * Optional header lines `KEY<TAB>VALUE...` before the column header row.
//     NO_OF_FRAMES, if present, must equal the number of data rows;
//     NO_OF_BODIES and BODY_NAMES, if present, must agree with the body blocks
//     found in the column header row; DATA_INCLUDED, if present, must be 6D.
//     Every other key (FREQUENCY, TIME_STAMP, EVENT, ...) is ignored.
//   * The column header row: its first column is `Frame`; then any columns
//     (Time, timecodes), then one block of 16 columns per rigid body:
//       `<name> X`, Y, Z, <three Euler angles>, Residual, Rot[0], ..., Rot[8].
//     The Euler columns are not used (their names and convention are a QTM
//     project setting); the rotation comes from Rot[0..8].
//   * One data row per captured frame, with the same columns; trailing empty
//     fields (QTM ends rows with a tab) are ignored.
//
// X, Y, Z are the body origin in the camera (global) frame in mm. Rot[0..8] is
// the body's rotation matrix in COLUMN-MAJOR order: Rot[k] = R(k % 3, k / 3),
// so Rot[0..2] is the body x axis in camera coordinates. QTM prints 5
// decimals, so matrices are accepted when max|R^T R - I| <= 1e-3 and
// projected onto the nearest rotation.
//
// A body counts as not tracked in a frame when any of its X, Y, Z, Residual
// or Rot values is NaN, or when all nine Rot values are 0.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cdcr/model/se3.hpp"
#include "dataset/csv_dataset.hpp"
#include "dataset/dataset.hpp"

namespace cdcr::dataset {

struct MocapFrame {
  int line = 0;           // line of the file, for messages
  long frame_number = 0;  // QTM's Frame column
  std::vector<std::optional<model::Pose<double>>> body_in_camera;  // MocapCapture::body_names order; empty = not tracked
};

struct MocapCapture {
  std::vector<std::string> body_names;
  int column_header_line = 0;
  std::vector<MocapFrame> frames;

  // Index into body_names, or -1.
  int body_index(std::string_view name) const;
};

// Throws DatasetError naming the line.
MocapCapture parse_qtm_6d_tsv(std::string_view text);
MocapCapture read_qtm_6d_tsv(const std::string& path);

// Eq. (21).
model::Pose<double> end_in_base(const model::Pose<double>& base_in_camera, const model::Pose<double>& end_in_camera);

enum class LostFrames { reject, skip };

// Under LostFrames::reject: a frame in which a body was not tracked.
class LostTrackingError : public DatasetError {
 public:
  using DatasetError::DatasetError;
};

struct MocapImportOptions {
  std::string base_body;
  std::string end_body;
  LostFrames lost_frames = LostFrames::reject;
};

struct MocapImport {
  Dataset data;                      // cables (and payloads, if any) of the kept rows, with their poses
  std::vector<long> skipped_frames;  // QTM frame numbers dropped because a body was lost
};

// Pairs commanded row i with captured frame i (the two must have the same
// count). Throws DatasetError: line 0 for a count mismatch, the column header
// line for a missing body; LostTrackingError with the frame's line for a lost
// body under LostFrames::reject.
//
// A motion sequence (the commanded file has t_s) keeps the commanded file's
// times and sessions: they say when each row was commanded and measured, on
// the clock the sequence was planned with (the capture's Time column is
// another clock and is not used). No row of a sequence can be dropped: a lost
// body there is a DatasetError with the frame's line, even under
// LostFrames::skip.
MocapImport import_mocap(const Dataset& commanded, const MocapCapture& capture, const MocapImportOptions& options);

}  // namespace cdcr::dataset
