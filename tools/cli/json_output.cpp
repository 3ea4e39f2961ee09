#include "json_output.hpp"

namespace cdcr::cli {

Json joints_to_json(const model::JointVector<double>& joints) {
  Json segments = Json::array();
  for (Eigen::Index i = 0; i < joints.size() / 2; ++i) {
    segments.push_back(Json::array({joints[2 * i], joints[2 * i + 1]}));
  }
  return segments;
}

Json cables_to_json(const model::CableVector<double>& cables_mm, const model::RobotGeometry<double>& geometry) {
  Json segments = Json::array();
  for (int i = 0; i < geometry.segment_count; ++i) {
    Json segment = Json::array();
    const int first = geometry.first_cable(i);
    for (int j = 0; j < geometry.segments[i].cables.count; ++j) segment.push_back(cables_mm[first + j]);
    segments.push_back(segment);
  }
  return segments;
}

Json pose_to_json(const model::Pose<double>& pose) {
  const model::Mat4<double> m = pose.matrix();
  Json rows = Json::array();
  for (int row = 0; row < 4; ++row) rows.push_back(Json::array({m(row, 0), m(row, 1), m(row, 2), m(row, 3)}));
  return rows;
}

}  // namespace cdcr::cli
