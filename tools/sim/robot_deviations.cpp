#include "sim/robot_deviations.hpp"

#include "sim/random_stream.hpp"

namespace cdcr::sim {
namespace {

using Vec3 = model::Vec3<double>;

Vec3 normal_vector(RandomStream& random, double sigma) {
  const double x = random.normal(sigma);
  const double y = random.normal(sigma);
  const double z = random.normal(sigma);
  return Vec3(x, y, z);
}

model::Pose<double> small_transform(const Vec3& rotation_vector, const Vec3& offset_mm) {
  return model::Pose<double>{model::exp_so3<double>(rotation_vector), offset_mm};
}

}  // namespace

RobotDeviations draw_deviations(int segment_count, const SimulatorConfig& config) {
  const GeometricErrorConfig& g = config.geometric;
  const CurvatureConfig& k = config.curvature;
  const double geometric = g.enabled ? 1.0 : 0.0;
  RandomStream random(config.seed, StreamId::robot);

  RobotDeviations d;
  for (int i = 0; i < segment_count; ++i) {
    SegmentDeviation& s = d.segments[i];
    s.backbone_length_error_mm = geometric * random.normal(g.backbone_length_sigma_mm);
    s.anchor_radius_error_mm = geometric * random.normal(g.anchor_radius_sigma_mm);
    s.anchor_angle_offset_rad = geometric * random.normal(g.anchor_angle_sigma_rad);
    const double gradient = k.gradient_mean + random.normal(k.gradient_sigma);
    s.curvature_gradient = k.enabled ? gradient : 0.0;
  }
  for (int i = 0; i + 1 < segment_count; ++i) {
    const double tilt_x = random.normal(g.segment_tilt_sigma_rad);
    const double tilt_y = random.normal(g.segment_tilt_sigma_rad);
    const double twist = random.normal(g.segment_twist_sigma_rad);
    const Vec3 offset = normal_vector(random, g.segment_offset_sigma_mm);
    d.segment_mounts[i] = small_transform(geometric * Vec3(tilt_x, tilt_y, twist), geometric * offset);
  }
  const Vec3 base_rotation = normal_vector(random, g.base_rotation_sigma_rad);
  const Vec3 base_offset = normal_vector(random, g.base_offset_sigma_mm);
  d.base_mount = small_transform(geometric * base_rotation, geometric * base_offset);
  const Vec3 platform_rotation = normal_vector(random, g.platform_rotation_sigma_rad);
  const Vec3 platform_offset = normal_vector(random, g.platform_offset_sigma_mm);
  d.platform_mount = small_transform(geometric * platform_rotation, geometric * platform_offset);
  return d;
}

}  // namespace cdcr::sim
