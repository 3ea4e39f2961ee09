#include "dataset/csv_dataset.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <vector>

#include "cdcr/model/limits.hpp"
#include "cdcr/model/unit_quaternion.hpp"
#include "dataset/field_parsing.hpp"

namespace cdcr::dataset {

namespace {

using detail::quoted;
using detail::kUtf8ByteOrderMark;
using detail::split_fields;
using detail::trim_blanks;

constexpr const char* kTimeColumn = "t_s";
constexpr const char* kPayloadColumn = "payload_kg";
constexpr const char* kPoseColumns[] = {"x", "y", "z", "qw", "qx", "qy", "qz"};
constexpr int kPoseColumnCount = 7;

std::string cable_column_name(int segment, int cable) {
  return "l" + std::to_string(segment + 1) + "_" + std::to_string(cable + 1);
}

double parse_number(std::string_view field, int line, const std::string& column) {
  double value = 0.0;
  switch (detail::parse_decimal(field, value)) {
    case detail::NumberStatus::ok: return value;
    case detail::NumberStatus::empty: throw DatasetError(line, "column " + column + ": empty field");
    case detail::NumberStatus::out_of_range:
      throw DatasetError(line, "column " + column + ": " + quoted(field) + " is out of the range of a double");
    case detail::NumberStatus::not_finite:
      throw DatasetError(line, "column " + column + ": " + quoted(field) + " is NaN or Inf");
    case detail::NumberStatus::not_a_number: break;
  }
  throw DatasetError(line, "column " + column + ": " + quoted(field) + " is not a number");
}

struct Header {
  int line = 0;
  int segment_count = 0;
  std::vector<int> segment_cables;
  std::vector<std::string> cable_names;
  bool has_time = false;
  bool has_payload = false;
  bool has_poses = false;

  int first_cable_column() const { return has_time ? 1 : 0; }
  int cable_columns() const { return static_cast<int>(cable_names.size()); }
  int payload_column() const { return first_cable_column() + cable_columns(); }
  int columns() const {
    return first_cable_column() + cable_columns() + (has_payload ? 1 : 0) + (has_poses ? kPoseColumnCount : 0);
  }
  std::string column_name(int index) const {
    if (has_time && index == 0) return kTimeColumn;
    const int cable = index - first_cable_column();
    if (cable < cable_columns()) return cable_names[static_cast<std::size_t>(cable)];
    if (has_payload && index == payload_column()) return kPayloadColumn;
    return kPoseColumns[index - payload_column() - (has_payload ? 1 : 0)];
  }
};

Header parse_header(std::string_view line, int line_number, PoseColumns poses) {
  const std::vector<std::string_view> fields = split_fields(line, ',');
  double ignored = 0.0;
  const detail::NumberStatus first = detail::parse_decimal(fields[0], ignored);
  if (first != detail::NumberStatus::not_a_number && first != detail::NumberStatus::empty) {
    throw DatasetError(line_number, "missing header: the first line must name the columns (l1_1,l1_2,...), found data");
  }
  // The time column has one place: first.
  const bool has_time = fields[0] == kTimeColumn;
  const int first_cable = has_time ? 1 : 0;
  for (int i = 1; i < static_cast<int>(fields.size()); ++i) {
    if (fields[i] == kTimeColumn) {
      throw DatasetError(line_number, "header column " + std::to_string(i + 1) + " is '" + kTimeColumn +
                                          "', which belongs first, before the cable columns");
    }
  }
  int cables = 0;
  while (first_cable + cables < static_cast<int>(fields.size()) && !fields[first_cable + cables].empty() &&
         fields[first_cable + cables][0] == 'l') {
    ++cables;
  }
  // The payload column has one place: right after the cable columns (not
  // between them).
  const auto cable_column_after = [&](int i) {
    return std::any_of(fields.begin() + i + 1, fields.end(),
                       [](std::string_view f) { return !f.empty() && f[0] == 'l'; });
  };
  for (int i = 0; i < static_cast<int>(fields.size()); ++i) {
    if (fields[i] == kPayloadColumn && (i != first_cable + cables || cables == 0 || cable_column_after(i))) {
      throw DatasetError(line_number, "header column " + std::to_string(i + 1) + " is '" + kPayloadColumn +
                                          "', which belongs right after the cable columns and before x,y,z,...");
    }
  }
  if (cables == 0) {
    throw DatasetError(line_number, std::string("header must start with ") + (has_time ? "t_s, then " : "") +
                                        "cable columns l1_1,l1_2,l1_3[,l1_4],l2_1,... (three or four a segment)");
  }
  Header h;
  h.line = line_number;
  h.has_time = has_time;
  // Segment by segment: li_1, li_2, ... then l(i+1)_1; each segment has the
  // cables a segment may have (three or four).
  const auto segment_complete = [&](int column) {
    const int count = h.segment_cables.back();
    if (count < model::kMinCablesPerSegment || count > model::kMaxCablesPerSegment) {
      throw DatasetError(line_number, "header column " + std::to_string(column) + ": segment " +
                                          std::to_string(h.segment_cables.size()) + " has " + std::to_string(count) +
                                          " cable columns; a segment has " +
                                          std::to_string(model::kMinCablesPerSegment) + " or " +
                                          std::to_string(model::kMaxCablesPerSegment));
    }
  };
  for (int i = 0; i < cables; ++i) {
    const std::string_view name = fields[first_cable + i];
    const int segment = static_cast<int>(h.segment_cables.size());
    const bool next_cable = segment > 0 && h.segment_cables.back() < model::kMaxCablesPerSegment &&
                            name == cable_column_name(segment - 1, h.segment_cables.back());
    if (next_cable) {
      h.segment_cables.back() += 1;
    } else if (name == cable_column_name(segment, 0)) {
      if (segment > 0) segment_complete(first_cable + i + 1);
      if (segment == model::kMaxSegments) {
        throw DatasetError(line_number, "header column " + std::to_string(first_cable + i + 1) + " is " +
                                            quoted(name) + ": more than the " + std::to_string(model::kMaxSegments) +
                                            " segments supported");
      }
      h.segment_cables.push_back(1);
    } else {
      std::string expected = "'" + cable_column_name(segment, 0) + "'";
      if (segment > 0 && h.segment_cables.back() < model::kMaxCablesPerSegment) {
        expected = "'" + cable_column_name(segment - 1, h.segment_cables.back()) + "' or " + expected;
      }
      throw DatasetError(line_number, "header column " + std::to_string(first_cable + i + 1) + " is " +
                                          quoted(name) + ", expected " + expected);
    }
    h.cable_names.emplace_back(name);
  }
  segment_complete(first_cable + cables);
  h.segment_count = static_cast<int>(h.segment_cables.size());
  h.has_payload = h.payload_column() < static_cast<int>(fields.size()) && fields[h.payload_column()] == kPayloadColumn;
  if (h.has_time && h.has_payload) {
    throw DatasetError(line_number, std::string("a time column (") + kTimeColumn + ") together with a payload column (" +
                                        kPayloadColumn + ") is not supported: record a motion sequence without "
                                        "payload, or payload samples without time");
  }
  const int first_pose = h.payload_column() + (h.has_payload ? 1 : 0);
  const int rest = static_cast<int>(fields.size()) - first_pose;
  if (rest == 0) {
    if (poses == PoseColumns::required) {
      throw DatasetError(line_number, std::string("missing pose columns x,y,z,qw,qx,qy,qz after the ") +
                                          (h.has_payload ? "payload column" : "cable columns"));
    }
    return h;
  }
  for (int i = 0; i < kPoseColumnCount; ++i) {
    if (first_pose + i >= static_cast<int>(fields.size())) {
      throw DatasetError(line_number, std::string("missing column '") + kPoseColumns[i] + "'");
    }
    if (fields[first_pose + i] != kPoseColumns[i]) {
      throw DatasetError(line_number, "header column " + std::to_string(first_pose + i + 1) + " is " +
                                          quoted(fields[first_pose + i]) + ", expected '" + kPoseColumns[i] + "'");
    }
  }
  if (rest > kPoseColumnCount) {
    throw DatasetError(line_number, "unexpected column " + quoted(fields[first_pose + kPoseColumnCount]));
  }
  h.has_poses = true;
  return h;
}

model::Pose<double> pose_from_fields(const double* p, int line_number) {
  Eigen::Quaterniond q(p[3], p[4], p[5], p[6]);  // (w, x, y, z)
  const double norm = q.norm();
  if (!model::is_unit_quaternion_norm(norm)) {
    std::ostringstream message;
    message << "quaternion norm " << norm << " is not 1 (tolerance " << model::kQuaternionNormTolerance << ")";
    throw DatasetError(line_number, message.str());
  }
  q.coeffs() /= norm;
  model::Pose<double> pose;
  pose.rotation = q.toRotationMatrix();
  pose.position_mm = Eigen::Vector3d(p[0], p[1], p[2]);
  return pose;
}

std::string one_line(const std::string& text) {
  std::string out = text;
  for (char& c : out) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return out;
}

}  // namespace

DatasetError::DatasetError(int line, const std::string& message) : DatasetError(std::string(), line, message) {}

DatasetError::DatasetError(const std::string& source, const DatasetError& error)
    : DatasetError(source, error.line(), error.message()) {}

DatasetError::DatasetError(const std::string& source, int line, const std::string& message)
    : std::runtime_error(one_line((source.empty() ? "" : source + ": ") +
                                  (line > 0 ? "line " + std::to_string(line) + ": " : "") + message)),
      line_(line),
      message_(message) {}

std::uint64_t fnv1a64(std::string_view bytes) {
  std::uint64_t hash = 0xcbf29ce484222325ull;
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ull;
  }
  return hash;
}

Dataset parse_dataset_csv(std::string_view text, PoseColumns poses) {
  Dataset data;
  data.content_hash = fnv1a64(text);
  // Spreadsheet programs like to start UTF-8 files with a byte order mark.
  if (text.substr(0, kUtf8ByteOrderMark.size()) == kUtf8ByteOrderMark) text.remove_prefix(kUtf8ByteOrderMark.size());

  Header header;
  bool have_header = false;
  std::vector<double> values;
  std::string previous_time;  // the last row's t_s field, for messages
  int rows_read = 0;
  detail::LineReader lines(text);
  for (std::string_view raw; lines.next(raw);) {
    const std::string_view line = trim_blanks(raw);
    const int line_number = lines.number();
    if (line.empty() || line.front() == '#') continue;
    if (!have_header) {
      header = parse_header(line, line_number, poses);
      have_header = true;
      continue;
    }
    const std::vector<std::string_view> fields = split_fields(line, ',');
    const int expected = header.columns();
    if (static_cast<int>(fields.size()) != expected) {
      throw DatasetError(line_number, "expected " + std::to_string(expected) + " fields, found " +
                                          std::to_string(fields.size()));
    }
    const std::size_t row_start = values.size();
    for (int i = 0; i < expected; ++i) values.push_back(parse_number(fields[i], line_number, header.column_name(i)));
    if (header.has_time) {
      const double time_s = values[row_start];
      if (rows_read > 0) {
        const double previous_s = values[row_start - static_cast<std::size_t>(expected)];
        if (!(time_s > previous_s)) {
          throw DatasetError(line_number, std::string("column ") + kTimeColumn + ": " + quoted(fields[0]) +
                                              " is not after the previous row's " + detail::quoted(std::string_view(previous_time)) +
                                              "; the time of a motion sequence must strictly increase");
        }
        if (time_s - previous_s > kSessionGapSeconds) data.session_starts.push_back(rows_read);
      } else {
        data.session_starts.push_back(0);
      }
      previous_time = std::string(fields[0]);
    }
    if (header.has_payload) {
      const std::size_t payload = row_start + static_cast<std::size_t>(header.payload_column());
      if (values[payload] < 0.0) {
        throw DatasetError(line_number, std::string("column ") + kPayloadColumn + ": " +
                                            quoted(fields[header.payload_column()]) +
                                            " is negative; a payload is a mass, zero or more kg");
      }
    }
    ++rows_read;
    if (header.has_poses) {
      data.poses.push_back(pose_from_fields(values.data() + values.size() - kPoseColumnCount, line_number));
    }
  }
  if (!have_header) throw DatasetError(0, "no header line (expected l1_1,l1_2,...): the file is empty or only comments");
  data.segment_count = header.segment_count;
  data.segment_cables = header.segment_cables;
  data.has_time = header.has_time;
  data.has_payload = header.has_payload;
  data.has_poses = header.has_poses;
  const int columns = header.columns();
  const auto rows = static_cast<Eigen::Index>(values.size() / static_cast<std::size_t>(columns));
  if (rows == 0) throw DatasetError(header.line, "no data rows after the header");
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> all(values.data(), rows,
                                                                                                     columns);
  data.cables_mm = all.middleCols(header.first_cable_column(), header.cable_columns());
  if (header.has_time) data.time_s = all.col(0);
  if (header.has_payload) data.payload_kg = all.col(header.payload_column());
  return data;
}

Dataset read_dataset_csv(const std::string& path, PoseColumns poses) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw DatasetError(path, DatasetError(0, "cannot open file"));
  std::ostringstream buffer;
  buffer << file.rdbuf();
  try {
    return parse_dataset_csv(buffer.str(), poses);
  } catch (const DatasetError& e) {
    throw DatasetError(path, e);
  }
}

std::vector<int> session_starts_from_times(const Eigen::VectorXd& time_s) {
  std::vector<int> starts;
  if (time_s.size() > 0) starts.push_back(0);
  for (Eigen::Index i = 1; i < time_s.size(); ++i) {
    if (time_s[i] - time_s[i - 1] > kSessionGapSeconds) starts.push_back(static_cast<int>(i));
  }
  return starts;
}

std::string format_dataset_csv(const Dataset& data, const std::string& comment) {
  if (data.segment_count < 1 || data.segment_count > model::kMaxSegments ||
      (!data.segment_cables.empty() && data.segment_cables.size() != static_cast<std::size_t>(data.segment_count)) ||
      data.cables_mm.cols() != data.cable_count()) {
    throw std::invalid_argument("dataset has " + std::to_string(data.cables_mm.cols()) + " cable columns for " +
                                std::to_string(data.segment_count) + " segments");
  }
  if (data.has_poses && data.poses.size() != static_cast<std::size_t>(data.sample_count())) {
    throw std::invalid_argument("dataset has " + std::to_string(data.poses.size()) + " poses for " +
                                std::to_string(data.sample_count()) + " samples");
  }
  if (data.has_payload) {
    if (data.payload_kg.size() != data.sample_count()) {
      throw std::invalid_argument("dataset has " + std::to_string(data.payload_kg.size()) + " payloads for " +
                                  std::to_string(data.sample_count()) + " samples");
    }
    if (!data.payload_kg.allFinite() || (data.payload_kg.array() < 0.0).any()) {
      throw std::invalid_argument("dataset has a payload that is NaN, Inf or negative");
    }
  }
  if (data.has_time) {
    if (data.has_payload) throw std::invalid_argument("dataset has both a time and a payload column: not supported");
    if (data.time_s.size() != data.sample_count()) {
      throw std::invalid_argument("dataset has " + std::to_string(data.time_s.size()) + " times for " +
                                  std::to_string(data.sample_count()) + " samples");
    }
    if (!data.time_s.allFinite()) throw std::invalid_argument("dataset has a time that is NaN or Inf");
    for (Eigen::Index i = 1; i < data.time_s.size(); ++i) {
      if (!(data.time_s[i] > data.time_s[i - 1])) {
        throw std::invalid_argument("dataset time does not strictly increase at row " + std::to_string(i + 1));
      }
    }
    if (data.session_starts != session_starts_from_times(data.time_s)) {
      throw std::invalid_argument("dataset session starts are not where the time has gaps of more than " +
                                  std::to_string(kSessionGapSeconds) + " s: a reader would split it differently");
    }
  }
  std::ostringstream out;
  out << std::setprecision(std::numeric_limits<double>::max_digits10);
  if (!comment.empty()) {
    std::istringstream lines(comment);
    for (std::string line; std::getline(lines, line);) out << "# " << line << '\n';
  }
  if (data.has_time) out << kTimeColumn << ',';
  for (int i = 0; i < data.segment_count; ++i) {
    for (int j = 0; j < data.cables_of(i); ++j) out << (i + j > 0 ? "," : "") << cable_column_name(i, j);
  }
  if (data.has_payload) out << ',' << kPayloadColumn;
  if (data.has_poses) {
    for (const char* c : kPoseColumns) out << ',' << c;
  }
  out << '\n';
  for (int r = 0; r < data.sample_count(); ++r) {
    if (data.has_time) out << data.time_s[r] << ',';
    for (Eigen::Index c = 0; c < data.cables_mm.cols(); ++c) out << (c ? "," : "") << data.cables_mm(r, c);
    if (data.has_payload) out << ',' << data.payload_kg[r];
    if (data.has_poses) {
      const model::Pose<double>& pose = data.poses[static_cast<std::size_t>(r)];
      const Eigen::Quaterniond q = model::with_positive_w(Eigen::Quaterniond(pose.rotation));
      out << ',' << pose.position_mm.x() << ',' << pose.position_mm.y() << ',' << pose.position_mm.z() << ','
          << q.w() << ',' << q.x() << ',' << q.y() << ',' << q.z();
    }
    out << '\n';
  }
  return out.str();
}

void write_dataset_csv(const std::string& path, const Dataset& data, const std::string& comment) {
  const std::string text = format_dataset_csv(data, comment);
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) throw DatasetError(path, DatasetError(0, "cannot open file for writing"));
  file << text;
  file.close();
  if (!file) throw DatasetError(path, DatasetError(0, "write failed"));
}

}  // namespace cdcr::dataset
