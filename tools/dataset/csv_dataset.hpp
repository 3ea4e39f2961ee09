#pragma once
// Reading and writing the dataset CSV (layout in tools/dataset/format.md).
//
//   [t_s,]l1_1,l1_2,l1_3,l1_4,...,ln_4[,payload_kg][,x,y,z,qw,qx,qy,qz]
//
// Optionally a time column first: the rows are then a motion sequence (the
// robot moved from row to row, and the order matters), t_s in seconds,
// strictly increasing; a gap above kSessionGapSeconds starts a new session.
// A time column and a payload column together are not supported. Then the
// cable columns (li_j: cable j of segment i, mm), then optionally the
// payload the end platform carried (kg, finite and not negative), then
// optionally the measured end-platform pose in the base frame (mm; unit
// quaternion, Hamilton, w first). Lines starting with '#' are comments; blank
// lines are ignored; LF and CRLF line endings are both accepted.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "dataset/dataset.hpp"

namespace cdcr::dataset {

// Every rejection names the file line (1-based, comments and blank lines
// included) it happened on, or 0 when it concerns the whole file; what() is a
// single line ready to print: "[source: ][line N: ]message".
class DatasetError : public std::runtime_error {
 public:
  DatasetError(int line, const std::string& message);
  // The same rejection, attributed to a file (or any other named source).
  DatasetError(const std::string& source, const DatasetError& error);

  int line() const { return line_; }
  const std::string& message() const { return message_; }

 private:
  DatasetError(const std::string& source, int line, const std::string& message);

  int line_;
  std::string message_;
};

enum class PoseColumns { optional, required };

// Parses CSV text. Quaternions whose norm is within 1e-3 of 1 are
// renormalised; beyond that the row is rejected.
Dataset parse_dataset_csv(std::string_view text, PoseColumns poses = PoseColumns::optional);

// Reads a file (errors are prefixed with the path).
Dataset read_dataset_csv(const std::string& path, PoseColumns poses = PoseColumns::optional);

// The first row of every session of a motion sequence: row 0, and every row
// more than kSessionGapSeconds after the one before.
std::vector<int> session_starts_from_times(const Eigen::VectorXd& time_s);

// Writes with full round-trip precision (max_digits10); the time is written
// when has_time, the payload when has_payload, poses when has_poses. Each
// line of `comment` becomes a '#' line before the header. Throws
// std::invalid_argument if the dataset's shapes disagree, or a payload, a
// time or a session start is one the reader would not read back.
std::string format_dataset_csv(const Dataset& data, const std::string& comment = {});
void write_dataset_csv(const std::string& path, const Dataset& data, const std::string& comment = {});

// 64-bit FNV-1a, the dataset hash recorded in model images.
std::uint64_t fnv1a64(std::string_view bytes);

}  // namespace cdcr::dataset
