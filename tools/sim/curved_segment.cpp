#include "sim/curved_segment.hpp"

#include <array>
#include <cmath>

#include <cdcr/model/series.hpp>

namespace cdcr::sim {
namespace {

// 8-point Gauss-Legendre rule on [-1, 1], symmetric: nodes +-x_k, weights w_k.
constexpr std::array<double, 4> kNodes = {0.1834346424956498049, 0.5255324099163289858, 0.7966664774136267396,
                                          0.9602898564975362317};
constexpr std::array<double, 4> kWeights = {0.3626837833783619830, 0.3137066458778872873, 0.2223810344533744706,
                                            0.1012285362903762592};
// Composite panels keep the rule accurate for bends up to and beyond pi.
constexpr int kPanels = 4;

}  // namespace

model::Pose<double> curved_segment_pose(const model::Vec2<double>& bend, double backbone_length_mm,
                                        double curvature_gradient, double fraction) {
  const double L = backbone_length_mm;
  const double c = curvature_gradient;
  const double theta = bend.norm();
  const auto turned_fraction = [&](double s) { return (s + c * (s * s / L - s)) / L; };

  const double s_end = fraction * L;
  const double panel = s_end / kPanels;
  double lateral = 0.0;  // I1
  double axial = 0.0;    // I2
  for (int p = 0; p < kPanels; ++p) {
    const double centre = (p + 0.5) * panel;
    for (std::size_t k = 0; k < kNodes.size(); ++k) {
      for (const double sign : {-1.0, 1.0}) {
        const double s = centre + sign * kNodes[k] * panel / 2.0;
        const double g = turned_fraction(s);
        const double weight = kWeights[k] * panel / 2.0;
        lateral += weight * g * model::series::sinc(theta * g);
        axial += weight * std::cos(theta * g);
      }
    }
  }

  model::Pose<double> pose;
  const double g_end = turned_fraction(s_end);
  pose.rotation = model::exp_so3<double>(g_end * model::Vec3<double>(-bend.y(), bend.x(), 0.0));
  pose.position_mm = model::Vec3<double>(bend.x() * lateral, bend.y() * lateral, axial);
  return pose;
}

}  // namespace cdcr::sim
