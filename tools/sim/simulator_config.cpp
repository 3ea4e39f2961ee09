#include "sim/simulator_config.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <cdcr/model/units.hpp>

namespace cdcr::sim {
namespace {

void require(bool condition, const std::string& message) {
  if (!condition) throw std::invalid_argument(message);
}

void require_sigma(double value, const char* name) {
  require(std::isfinite(value) && value >= 0.0, std::string(name) + " must be finite and not negative");
}

}  // namespace

SimulatorConfig SimulatorConfig::nominal_only() {
  SimulatorConfig config;
  config.geometric.enabled = false;
  config.curvature.enabled = false;
  config.compliance.enabled = false;
  config.gravity.enabled = false;
  config.repeatability.enabled = false;
  config.mocap_noise.enabled = false;
  return config;
}

void SimulatorConfig::use_hysteresis_session() {
  hysteresis.enabled = true;
  repeatability.bend_sigma_rad = HysteresisSessionDefaults::kRepeatabilitySigmaRad;
  mocap_noise.position_sigma_mm = HysteresisSessionDefaults::kMocapPositionSigmaMm;
  mocap_noise.rotation_sigma_rad = HysteresisSessionDefaults::kMocapRotationSigmaRad;
}

void SimulatorConfig::validate() const {
  require(std::isfinite(workspace_theta_max_rad) && workspace_theta_max_rad > 0.0 &&
              workspace_theta_max_rad <= model::kPi,
          "workspace theta_max must be in (0, pi] rad");

  require(std::isfinite(structure.backbone_bending_stiffness_n_mm2) && structure.backbone_bending_stiffness_n_mm2 > 0.0,
          "backbone bending stiffness must be positive");
  require(std::isfinite(structure.cable_stiffness_n_per_mm) && structure.cable_stiffness_n_per_mm > 0.0,
          "cable stiffness must be positive");

  const GeometricErrorConfig& g = geometric;
  require_sigma(g.backbone_length_sigma_mm, "backbone length sigma");
  require_sigma(g.anchor_radius_sigma_mm, "anchor radius sigma");
  require_sigma(g.anchor_angle_sigma_rad, "anchor angle sigma");
  require_sigma(g.segment_twist_sigma_rad, "segment twist sigma");
  require_sigma(g.segment_tilt_sigma_rad, "segment tilt sigma");
  require_sigma(g.segment_offset_sigma_mm, "segment offset sigma");
  require_sigma(g.base_rotation_sigma_rad, "base rotation sigma");
  require_sigma(g.base_offset_sigma_mm, "base offset sigma");
  require_sigma(g.platform_rotation_sigma_rad, "platform rotation sigma");
  require_sigma(g.platform_offset_sigma_mm, "platform offset sigma");

  require(std::isfinite(curvature.gradient_mean) && std::abs(curvature.gradient_mean) < 1.0,
          "curvature gradient mean must lie in (-1, 1)");
  require_sigma(curvature.gradient_sigma, "curvature gradient sigma");

  require(gravity.direction.allFinite() && gravity.direction.norm() > 0.0, "gravity direction must be a non-zero vector");
  require(std::isfinite(gravity.acceleration_m_per_s2) && gravity.acceleration_m_per_s2 >= 0.0,
          "gravitational acceleration must be finite and not negative");
  require(std::isfinite(gravity.segment_mass_kg) && gravity.segment_mass_kg >= 0.0,
          "segment mass must be finite and not negative");
  require(std::isfinite(gravity.platform_mass_kg) && gravity.platform_mass_kg >= 0.0,
          "platform mass must be finite and not negative");
  require(std::isfinite(payload.min_kg) && std::isfinite(payload.max_kg) && payload.min_kg >= 0.0 &&
              payload.min_kg <= payload.max_kg,
          "payload range must satisfy 0 <= min <= max (kg), both finite");

  require_sigma(repeatability.bend_sigma_rad, "repeatability sigma");
  require_sigma(mocap_noise.position_sigma_mm, "mocap position sigma");
  require_sigma(mocap_noise.rotation_sigma_rad, "mocap rotation sigma");

  const HysteresisConfig& h = hysteresis;
  require(std::isfinite(h.max_lag_min_mm) && std::isfinite(h.max_lag_max_mm) && h.max_lag_min_mm >= 0.0 &&
              h.max_lag_min_mm <= h.max_lag_max_mm,
          "hysteresis maximum lag range must satisfy 0 <= min <= max (mm), both finite");
  require(std::isfinite(h.total_weight_min) && std::isfinite(h.total_weight_max) && h.total_weight_min > 0.0 &&
              h.total_weight_min <= h.total_weight_max && h.total_weight_max <= 1.0,
          "hysteresis total weight range must satisfy 0 < min <= max <= 1");
  require(std::isfinite(h.density_slope_max) && h.density_slope_max >= 0.0 && h.density_slope_max < 1.0,
          "hysteresis density slope must lie in [0, 1)");
  require(std::isfinite(motion.cable_speed_mm_per_s) && motion.cable_speed_mm_per_s > 0.0,
          "motion sequence cable speed must be positive");
  require(std::isfinite(motion.settle_s) && motion.settle_s > 0.0,
          "motion sequence settling time must be positive");
}

}  // namespace cdcr::sim
