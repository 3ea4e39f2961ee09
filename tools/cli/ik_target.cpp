#include "ik_target.hpp"

#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <fmt/format.h>

#include "cli_errors.hpp"
#include "number_list.hpp"

namespace cdcr::cli {

model::Vec3<double> position_from_values(const std::vector<double>& values) {
  require_count(values, 3, "--position", "X,Y,Z in mm");
  require_finite(values, "--position");
  return model::Vec3<double>(values[0], values[1], values[2]);
}

model::Mat3<double> rotation_from_quaternion(const std::vector<double>& values) {
  require_count(values, 4, "--quaternion", "QW,QX,QY,QZ");
  require_finite(values, "--quaternion");
  Eigen::Quaterniond quaternion(values[0], values[1], values[2], values[3]);
  const double norm = quaternion.norm();
  if (!model::is_unit_quaternion_norm(norm)) {
    throw InputError(fmt::format("--quaternion: not a unit quaternion (norm {:g}, allowed deviation from 1 is {:g})",
                                 norm, model::kQuaternionNormTolerance));
  }
  quaternion.normalize();
  return quaternion.toRotationMatrix();
}

model::Pose<double> pose_from_row_major(const std::vector<double>& values) {
  if (values.size() != 12 && values.size() != 16) {
    throw InputError(fmt::format("--pose: expected 12 or 16 values (row-major [R p; 0 0 0 1]), got {}", values.size()));
  }
  require_finite(values, "--pose");
  model::Mat4<double> matrix = model::Mat4<double>::Identity();
  for (std::size_t k = 0; k < values.size(); ++k) matrix(static_cast<Eigen::Index>(k / 4), k % 4) = values[k];

  if (values.size() == 16) {
    const double deviation = (matrix.row(3) - Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0)).cwiseAbs().maxCoeff();
    if (deviation > kRotationOrthonormalityTolerance) {
      throw InputError(fmt::format("--pose: the last row must be 0,0,0,1 (got {},{},{},{})", matrix(3, 0),
                                   matrix(3, 1), matrix(3, 2), matrix(3, 3)));
    }
  }

  const model::Mat3<double> rotation = matrix.topLeftCorner<3, 3>();
  const double orthonormality_error =
      (rotation.transpose() * rotation - model::Mat3<double>::Identity()).cwiseAbs().maxCoeff();
  if (orthonormality_error > kRotationOrthonormalityTolerance) {
    throw InputError(fmt::format("--pose: rotation is not orthonormal (max |R^T R - I| = {:.3g} > {:g})",
                                 orthonormality_error, kRotationOrthonormalityTolerance));
  }
  if (rotation.determinant() < 0.0) {
    throw InputError("--pose: rotation is a reflection (determinant -1), not a rotation");
  }

  const Eigen::JacobiSVD<model::Mat3<double>> svd(rotation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  model::Pose<double> pose;
  pose.rotation = svd.matrixU() * svd.matrixV().transpose();
  pose.position_mm = matrix.topRightCorner<3, 1>();
  return pose;
}

}  // namespace cdcr::cli
