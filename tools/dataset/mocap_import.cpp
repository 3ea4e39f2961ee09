#include "dataset/mocap_import.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include <Eigen/LU>

#include "dataset/field_parsing.hpp"

namespace cdcr::dataset {

namespace {

using detail::quoted;
using detail::kUtf8ByteOrderMark;
using detail::trim_blanks;

constexpr int kBlockColumns = 16;  // X Y Z, three angles, Residual, Rot[0..8]
constexpr int kResidualOffset = 6;
constexpr int kRotationOffset = 7;
constexpr double kOrthonormalityTolerance = 1e-3;

// QTM may end a row with a tab; the empty fields that leaves are not columns.
std::vector<std::string_view> split_tabs(std::string_view line) {
  std::vector<std::string_view> fields = detail::split_fields(line, '\t');
  while (fields.size() > 1 && fields.back().empty()) fields.pop_back();
  return fields;
}

std::string rotation_column(int k) { return "Rot[" + std::to_string(k) + "]"; }

long parse_count(std::string_view field, int line, std::string_view what) {
  long value = 0;
  const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
  if (field.empty() || ec != std::errc() || ptr != field.data() + field.size() || value < 0) {
    throw DatasetError(line, std::string(what) + ": " + quoted(field) + " is not a non-negative integer");
  }
  return value;
}

struct BodyBlock {
  std::string name;
  int first_column = 0;
};

// Finds the 16-column blocks in the column header row.
std::vector<BodyBlock> find_body_blocks(const std::vector<std::string_view>& columns, int line) {
  std::vector<BodyBlock> blocks;
  for (int i = 1; i < static_cast<int>(columns.size());) {
    const std::string_view title = columns[static_cast<std::size_t>(i)];
    if (title.size() < 3 || title.substr(title.size() - 2) != " X") {
      ++i;
      continue;
    }
    const std::string name(trim_blanks(title.substr(0, title.size() - 2)));
    const auto column = [&](int offset) { return columns[static_cast<std::size_t>(i + offset)]; };
    bool complete = i + kBlockColumns <= static_cast<int>(columns.size()) && column(1) == "Y" && column(2) == "Z" &&
                    column(kResidualOffset) == "Residual";
    for (int k = 0; complete && k < 9; ++k) complete = column(kRotationOffset + k) == rotation_column(k);
    if (!complete) {
      throw DatasetError(line, "column " + std::to_string(i + 1) + ": body " + quoted(name) +
                                   " must have the 16 columns X, Y, Z, three angles, Residual, Rot[0], ..., Rot[8]");
    }
    blocks.push_back({name, i});
    i += kBlockColumns;
  }
  return blocks;
}

// Newton iteration for the orthogonal polar factor, R <- (R + R^-T) / 2: it
// converges quadratically from the nearly orthonormal matrices accepted here,
// and leaves an exactly orthonormal matrix with exact entries untouched.
Eigen::Matrix3d nearest_rotation(Eigen::Matrix3d r) {
  for (int iteration = 0; iteration < 8; ++iteration) {
    const Eigen::Matrix3d next = 0.5 * (r + r.inverse().transpose());
    const double change = (next - r).cwiseAbs().maxCoeff();
    r = next;
    if (change <= 4 * std::numeric_limits<double>::epsilon()) break;
  }
  return r;
}

std::string block_column_name(int offset) {
  if (offset < 3) return std::string(1, "XYZ"[offset]);
  if (offset < kResidualOffset) return "angle " + std::to_string(offset - 2);
  if (offset == kResidualOffset) return "Residual";
  return rotation_column(offset - kRotationOffset);
}

std::optional<model::Pose<double>> parse_body(const std::vector<std::string_view>& fields, const BodyBlock& block,
                                              int line) {
  double values[kBlockColumns];
  for (int k = 0; k < kBlockColumns; ++k) {
    const std::string_view field = fields[static_cast<std::size_t>(block.first_column + k)];
    const auto where = [&] { return "body " + quoted(block.name) + " " + block_column_name(k) + ": "; };
    switch (detail::parse_decimal(field, values[k])) {
      case detail::NumberStatus::ok: continue;
      case detail::NumberStatus::not_finite:
        if (std::isnan(values[k])) continue;
        throw DatasetError(line, where() + "value is infinite");
      case detail::NumberStatus::empty: throw DatasetError(line, where() + "empty field");
      case detail::NumberStatus::out_of_range:
      case detail::NumberStatus::not_a_number: break;
    }
    throw DatasetError(line, where() + quoted(field) + " is not a number");
  }
  // The Euler angles may be NaN at a singular orientation of a tracked body;
  // only the values the pose is made of decide whether it was tracked.
  bool lost = false;
  for (int k = 0; k < kBlockColumns; ++k) {
    if ((k < 3 || k >= kResidualOffset) && std::isnan(values[k])) lost = true;
  }
  Eigen::Matrix3d rotation;
  for (int k = 0; k < 9; ++k) rotation(k % 3, k / 3) = values[kRotationOffset + k];
  if (lost || rotation.isZero(0.0)) return std::nullopt;

  const double orthonormality_error = (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(orthonormality_error <= kOrthonormalityTolerance) || rotation.determinant() <= 0) {
    std::ostringstream message;
    message << "body " << quoted(block.name) << ": Rot[0..8] is not a rotation matrix (max |R^T R - I| = "
            << orthonormality_error << ", det = " << rotation.determinant() << ")";
    throw DatasetError(line, message.str());
  }
  model::Pose<double> pose;
  pose.rotation = nearest_rotation(rotation);
  pose.position_mm = Eigen::Vector3d(values[0], values[1], values[2]);
  return pose;
}

struct FileHeader {
  std::optional<long> frame_count;
  std::optional<long> body_count;
  std::optional<std::vector<std::string>> body_names;
  int body_names_line = 0;
};

void read_header_line(const std::vector<std::string_view>& fields, int line, FileHeader& header) {
  const std::string_view key = fields[0];
  const auto value = [&]() -> std::string_view {
    if (fields.size() < 2) throw DatasetError(line, std::string(key) + " has no value");
    return fields[1];
  };
  if (key == "NO_OF_FRAMES") {
    header.frame_count = parse_count(value(), line, key);
  } else if (key == "NO_OF_BODIES") {
    header.body_count = parse_count(value(), line, key);
  } else if (key == "DATA_INCLUDED") {
    if (value() != "6D") throw DatasetError(line, "DATA_INCLUDED is " + quoted(value()) + ", expected 6D (a 6DOF export)");
  } else if (key == "BODY_NAMES") {
    header.body_names.emplace(fields.begin() + 1, fields.end());
    header.body_names_line = line;
  }
}

}  // namespace

int MocapCapture::body_index(std::string_view name) const {
  for (std::size_t i = 0; i < body_names.size(); ++i) {
    if (body_names[i] == name) return static_cast<int>(i);
  }
  return -1;
}

MocapCapture parse_qtm_6d_tsv(std::string_view text) {
  if (text.substr(0, kUtf8ByteOrderMark.size()) == kUtf8ByteOrderMark) text.remove_prefix(kUtf8ByteOrderMark.size());
  MocapCapture capture;
  FileHeader header;
  std::vector<BodyBlock> blocks;
  std::size_t column_count = 0;
  detail::LineReader lines(text);
  for (std::string_view raw; lines.next(raw);) {
    const int line = lines.number();
    if (trim_blanks(raw).empty()) continue;
    const std::vector<std::string_view> fields = split_tabs(raw);
    if (capture.column_header_line == 0) {
      if (fields[0] != "Frame") {
        read_header_line(fields, line, header);
        continue;
      }
      capture.column_header_line = line;
      column_count = fields.size();
      blocks = find_body_blocks(fields, line);
      if (blocks.empty()) throw DatasetError(line, "no rigid body columns ('<name> X', Y, Z, ...) in the column header row");
      for (const BodyBlock& block : blocks) capture.body_names.push_back(block.name);
      if (header.body_count && *header.body_count != static_cast<long>(blocks.size())) {
        throw DatasetError(line, "NO_OF_BODIES is " + std::to_string(*header.body_count) + " but the columns hold " +
                                     std::to_string(blocks.size()) + " bodies");
      }
      if (header.body_names && *header.body_names != capture.body_names) {
        throw DatasetError(header.body_names_line, "BODY_NAMES does not match the body columns of line " +
                                                       std::to_string(line));
      }
      continue;
    }
    if (fields.size() != column_count) {
      throw DatasetError(line, "expected " + std::to_string(column_count) + " tab-separated fields, found " +
                                   std::to_string(fields.size()));
    }
    MocapFrame frame;
    frame.line = line;
    frame.frame_number = parse_count(fields[0], line, "Frame");
    for (const BodyBlock& block : blocks) frame.body_in_camera.push_back(parse_body(fields, block, line));
    capture.frames.push_back(std::move(frame));
  }
  if (capture.column_header_line == 0) {
    throw DatasetError(0, "no column header row (a line starting with 'Frame'): not a QTM 6DOF TSV export");
  }
  if (capture.frames.empty()) throw DatasetError(capture.column_header_line, "no frames after the column header row");
  if (header.frame_count && *header.frame_count != static_cast<long>(capture.frames.size())) {
    throw DatasetError(0, "NO_OF_FRAMES is " + std::to_string(*header.frame_count) + " but the file holds " +
                              std::to_string(capture.frames.size()) + " frames (truncated export?)");
  }
  return capture;
}

MocapCapture read_qtm_6d_tsv(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw DatasetError(path, DatasetError(0, "cannot open file"));
  std::ostringstream buffer;
  buffer << file.rdbuf();
  try {
    return parse_qtm_6d_tsv(buffer.str());
  } catch (const DatasetError& e) {
    throw DatasetError(path, e);
  }
}

model::Pose<double> end_in_base(const model::Pose<double>& base_in_camera, const model::Pose<double>& end_in_camera) {
  return base_in_camera.inverse() * end_in_camera;
}

MocapImport import_mocap(const Dataset& commanded, const MocapCapture& capture, const MocapImportOptions& options) {
  const auto body = [&](const std::string& name, const char* role) {
    const int index = capture.body_index(name);
    if (index < 0) {
      std::string known;
      for (const std::string& n : capture.body_names) known += (known.empty() ? "" : ", ") + quoted(n);
      throw DatasetError(capture.column_header_line,
                         std::string(role) + " body " + quoted(name) + " is not in the capture (bodies: " + known + ")");
    }
    return static_cast<std::size_t>(index);
  };
  const std::size_t base = body(options.base_body, "base");
  const std::size_t end = body(options.end_body, "end");
  if (capture.frames.size() != static_cast<std::size_t>(commanded.sample_count())) {
    throw DatasetError(0, "the capture has " + std::to_string(capture.frames.size()) +
                              " frames but the commanded cable file has " + std::to_string(commanded.sample_count()) +
                              " rows; they are paired one to one");
  }

  MocapImport result;
  std::vector<Eigen::Index> kept_rows;
  for (std::size_t i = 0; i < capture.frames.size(); ++i) {
    const MocapFrame& frame = capture.frames[i];
    const auto& base_pose = frame.body_in_camera[base];
    const auto& end_pose = frame.body_in_camera[end];
    if (!base_pose || !end_pose) {
      const std::string& lost = !base_pose ? options.base_body : options.end_body;
      if (commanded.has_time) {
        // The robot still moved through the row; without it the path from
        // row to row, which the hysteresis depends on, would be wrong.
        throw DatasetError(frame.line, "frame " + std::to_string(frame.frame_number) + ": body " + quoted(lost) +
                                           " was not tracked, and a row of a motion sequence (t_s) cannot be dropped");
      }
      if (options.lost_frames == LostFrames::skip) {
        result.skipped_frames.push_back(frame.frame_number);
        continue;
      }
      throw LostTrackingError(frame.line, "frame " + std::to_string(frame.frame_number) + ": body " + quoted(lost) +
                                              " was not tracked");
    }
    const model::Pose<double> pose = end_in_base(*base_pose, *end_pose);
    // Each coordinate is finite, but differences of values near the double
    // range can overflow; such a pose could not be written.
    if (!pose.all_finite()) {
      throw DatasetError(frame.line, "frame " + std::to_string(frame.frame_number) +
                                         ": the end-platform pose in the base frame overflows (coordinates out of range)");
    }
    kept_rows.push_back(static_cast<Eigen::Index>(i));
    result.data.poses.push_back(pose);
  }
  if (kept_rows.empty()) throw DatasetError(0, "no frame has both bodies tracked");
  result.data.segment_count = commanded.segment_count;
  result.data.segment_cables = commanded.segment_cables;
  result.data.has_poses = true;
  result.data.cables_mm = commanded.cables_mm(kept_rows, Eigen::all);
  result.data.has_payload = commanded.has_payload;
  if (commanded.has_payload) result.data.payload_kg = commanded.payload_kg(kept_rows);
  // A motion sequence keeps its commanded times (no row is dropped from one).
  result.data.has_time = commanded.has_time;
  if (commanded.has_time) {
    result.data.time_s = commanded.time_s;
    result.data.session_starts = commanded.session_starts;
  }
  return result;
}

}  // namespace cdcr::dataset
