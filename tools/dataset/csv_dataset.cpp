#include "dataset/csv_dataset.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <vector>

#include "cdcr/model/limits.hpp"

namespace cdcr::dataset {

namespace {

constexpr const char* kPoseColumns[] = {"x", "y", "z", "qw", "qx", "qy", "qz"};
constexpr int kPoseColumnCount = 7;
constexpr double kQuaternionNormTolerance = 1e-3;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

std::string cable_column_name(int segment, int cable) {
  return "l" + std::to_string(segment + 1) + "_" + std::to_string(cable + 1);
}

// Strict number parsing: the whole field must be a finite decimal number.
double parse_number(std::string_view field, int line, const std::string& column) {
  double value = 0.0;
  const char* begin = field.data();
  const char* end = field.data() + field.size();
  if (!field.empty() && *begin == '+') ++begin;
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (field.empty() || ec != std::errc() || ptr != end) {
    throw DatasetError(line, "column " + column + ": '" + std::string(field) + "' is not a number");
  }
  if (!std::isfinite(value)) throw DatasetError(line, "column " + column + ": value is NaN or Inf");
  return value;
}

struct Header {
  int segment_count = 0;
  bool has_poses = false;
};

Header parse_header(std::string_view line, int line_number, PoseColumns poses) {
  const std::vector<std::string_view> fields = split_fields(line);
  int cables = 0;
  while (cables < static_cast<int>(fields.size()) && !fields[cables].empty() && fields[cables][0] == 'l') ++cables;
  if (cables == 0 || cables % 4 != 0) {
    throw DatasetError(line_number, "header must start with cable columns l1_1,l1_2,l1_3,l1_4,... (a multiple of 4), found " +
                                        std::to_string(cables));
  }
  Header h;
  h.segment_count = cables / 4;
  if (h.segment_count > model::kMaxSegments) {
    throw DatasetError(line_number, std::to_string(h.segment_count) + " segments exceed the maximum of " +
                                        std::to_string(model::kMaxSegments));
  }
  for (int i = 0; i < cables; ++i) {
    const std::string expected = cable_column_name(i / 4, i % 4);
    if (fields[i] != expected) {
      throw DatasetError(line_number, "header column " + std::to_string(i + 1) + " is '" + std::string(fields[i]) +
                                          "', expected '" + expected + "'");
    }
  }
  const int rest = static_cast<int>(fields.size()) - cables;
  if (rest == 0) {
    if (poses == PoseColumns::required) {
      throw DatasetError(line_number, "missing pose columns x,y,z,qw,qx,qy,qz after the cable columns");
    }
    return h;
  }
  for (int i = 0; i < kPoseColumnCount; ++i) {
    if (cables + i >= static_cast<int>(fields.size())) {
      throw DatasetError(line_number, std::string("missing column '") + kPoseColumns[i] + "'");
    }
    if (fields[cables + i] != kPoseColumns[i]) {
      throw DatasetError(line_number, "header column " + std::to_string(cables + i + 1) + " is '" +
                                          std::string(fields[cables + i]) + "', expected '" + kPoseColumns[i] + "'");
    }
  }
  if (rest > kPoseColumnCount) {
    throw DatasetError(line_number, "unexpected column '" + std::string(fields[cables + kPoseColumnCount]) + "'");
  }
  h.has_poses = true;
  return h;
}

}  // namespace

DatasetError::DatasetError(int line, const std::string& message)
    : std::runtime_error(line > 0 ? "line " + std::to_string(line) + ": " + message : message), line_(line) {}

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
  Header header;
  bool have_header = false;
  std::vector<double> values;
  int line_number = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = trim(text.substr(start, end - start));
    start = end + 1;
    ++line_number;
    if (line.empty() || line.front() == '#') continue;
    if (!have_header) {
      header = parse_header(line, line_number, poses);
      have_header = true;
      continue;
    }
    const std::vector<std::string_view> fields = split_fields(line);
    const int cables = 4 * header.segment_count;
    const int expected = cables + (header.has_poses ? kPoseColumnCount : 0);
    if (static_cast<int>(fields.size()) != expected) {
      throw DatasetError(line_number, "expected " + std::to_string(expected) + " fields, found " +
                                          std::to_string(fields.size()));
    }
    for (int i = 0; i < expected; ++i) {
      const std::string column = i < cables ? cable_column_name(i / 4, i % 4) : kPoseColumns[i - cables];
      values.push_back(parse_number(fields[i], line_number, column));
    }
    if (header.has_poses) {
      const double* p = values.data() + values.size() - kPoseColumnCount;
      Eigen::Quaterniond q(p[3], p[4], p[5], p[6]);
      const double norm = q.norm();
      if (std::abs(norm - 1.0) > kQuaternionNormTolerance) {
        std::ostringstream message;
        message << "quaternion norm " << norm << " is not 1 (tolerance " << kQuaternionNormTolerance << ")";
        throw DatasetError(line_number, message.str());
      }
      q.normalize();
      model::Pose<double> pose;
      pose.rotation = q.toRotationMatrix();
      pose.position_mm = Eigen::Vector3d(p[0], p[1], p[2]);
      data.poses.push_back(pose);
    }
  }
  if (!have_header) throw DatasetError(0, "no header line (expected l1_1,l1_2,...)");
  data.segment_count = header.segment_count;
  data.has_poses = header.has_poses;
  const int columns = 4 * header.segment_count + (header.has_poses ? kPoseColumnCount : 0);
  const auto rows = static_cast<Eigen::Index>(values.size() / static_cast<std::size_t>(columns));
  if (rows == 0) throw DatasetError(0, "no data rows");
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> all(values.data(), rows,
                                                                                                     columns);
  data.cables_mm = all.leftCols(4 * header.segment_count);
  return data;
}

Dataset read_dataset_csv(const std::string& path, PoseColumns poses) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw DatasetError(0, path + ": cannot open file");
  std::ostringstream buffer;
  buffer << file.rdbuf();
  try {
    return parse_dataset_csv(buffer.str(), poses);
  } catch (const DatasetError& e) {
    throw DatasetError(0, path + ": " + e.what());
  }
}

std::string format_dataset_csv(const Dataset& data, const std::string& comment) {
  std::ostringstream out;
  out << std::setprecision(std::numeric_limits<double>::max_digits10);
  if (!comment.empty()) {
    std::istringstream lines(comment);
    for (std::string line; std::getline(lines, line);) out << "# " << line << '\n';
  }
  for (int i = 0; i < 4 * data.segment_count; ++i) out << (i ? "," : "") << cable_column_name(i / 4, i % 4);
  if (data.has_poses) {
    for (const char* c : kPoseColumns) out << ',' << c;
  }
  out << '\n';
  for (int r = 0; r < data.sample_count(); ++r) {
    for (Eigen::Index c = 0; c < data.cables_mm.cols(); ++c) out << (c ? "," : "") << data.cables_mm(r, c);
    if (data.has_poses) {
      const model::Pose<double>& pose = data.poses[static_cast<std::size_t>(r)];
      Eigen::Quaterniond q(pose.rotation);
      if (q.w() < 0) q.coeffs() = -q.coeffs();  // one canonical sign
      out << ',' << pose.position_mm.x() << ',' << pose.position_mm.y() << ',' << pose.position_mm.z() << ','
          << q.w() << ',' << q.x() << ',' << q.y() << ',' << q.z();
    }
    out << '\n';
  }
  return out.str();
}

void write_dataset_csv(const std::string& path, const Dataset& data, const std::string& comment) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) throw DatasetError(0, path + ": cannot open file for writing");
  file << format_dataset_csv(data, comment);
  if (!file) throw DatasetError(0, path + ": write failed");
}

}  // namespace cdcr::dataset
