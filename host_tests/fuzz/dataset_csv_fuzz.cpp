// Fuzzes the dataset CSV reader (tools/dataset/csv_dataset.cpp). Accepted
// text must give a consistent dataset that survives format -> parse exactly;
// rejected text must give one DatasetError line naming its line.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "dataset/csv_dataset.hpp"
#include "fuzz_checks.hpp"

namespace {

using cdcr::fuzz::check_rejection;
using cdcr::fuzz::require;
using namespace cdcr::dataset;

void check_accepted(const Dataset& data, std::string_view text, PoseColumns poses) {
  require(data.segment_count >= 1 && data.segment_count <= 8);
  // A segment has three or four cables; all four is written as no list at all.
  require(data.segment_cables.empty() ||
          data.segment_cables.size() == static_cast<std::size_t>(data.segment_count));
  for (const int cables : data.segment_cables) require(cables == 3 || cables == 4);
  require(data.cables_mm.cols() == data.cable_count());
  require(data.sample_count() >= 1);
  require(data.cables_mm.allFinite());
  require(data.content_hash == fnv1a64(text));
  require(poses == PoseColumns::optional || data.has_poses);
  require(data.poses.size() == (data.has_poses ? static_cast<std::size_t>(data.sample_count()) : 0u));
  require(data.payload_kg.size() == (data.has_payload ? data.sample_count() : 0));
  require(data.payload_kg.allFinite() && (data.payload_kg.array() >= 0.0).all());
  // A motion sequence: strictly increasing, split where the gaps are; never with a payload.
  require(data.time_s.size() == (data.has_time ? data.sample_count() : 0));
  require(!(data.has_time && data.has_payload));
  for (Eigen::Index i = 1; i < data.time_s.size(); ++i) require(data.time_s[i] > data.time_s[i - 1]);
  require(data.has_time ? data.session_starts == session_starts_from_times(data.time_s)
                        : data.session_starts.empty());
  for (const auto& pose : data.poses) {
    require(pose.all_finite());
    const double orthonormality = (pose.rotation.transpose() * pose.rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    require(orthonormality < 1e-12);
  }

  const Dataset back = parse_dataset_csv(format_dataset_csv(data, "fuzz"), poses);
  require(back.segment_count == data.segment_count && back.has_poses == data.has_poses);
  for (int i = 0; i < data.segment_count; ++i) require(back.cables_of(i) == data.cables_of(i));
  require(back.has_payload == data.has_payload && back.payload_kg.size() == data.payload_kg.size());
  require(back.has_time == data.has_time && back.time_s.size() == data.time_s.size());
  require(back.session_starts == data.session_starts);
  for (Eigen::Index i = 0; i < data.time_s.size(); ++i) {
    const double a = data.time_s[i];
    const double b = back.time_s[i];
    require(a == b && std::signbit(a) == std::signbit(b));
  }
  for (Eigen::Index i = 0; i < data.payload_kg.size(); ++i) {
    const double a = data.payload_kg[i];
    const double b = back.payload_kg[i];
    require(a == b && std::signbit(a) == std::signbit(b));
  }
  require(back.cables_mm.rows() == data.cables_mm.rows());
  for (Eigen::Index i = 0; i < data.cables_mm.size(); ++i) {
    const double a = data.cables_mm.data()[i];
    const double b = back.cables_mm.data()[i];
    require(a == b && std::signbit(a) == std::signbit(b));
  }
  for (std::size_t i = 0; i < data.poses.size(); ++i) {
    require(back.poses[i].position_mm == data.poses[i].position_mm);
    require((back.poses[i].rotation - data.poses[i].rotation).cwiseAbs().maxCoeff() < 1e-12);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (const PoseColumns poses : {PoseColumns::optional, PoseColumns::required}) {
    try {
      check_accepted(parse_dataset_csv(text, poses), text, poses);
    } catch (const DatasetError& e) {
      check_rejection(e);
    }
  }
  return 0;
}
