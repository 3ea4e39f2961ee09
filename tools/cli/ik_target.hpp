#pragma once
// Targets for the inverse kinematics, read from the command line: a position,
// a position with a unit quaternion, or a homogeneous matrix as printed by
// `cdcr fk --json`.

#include <vector>

#include <cdcr/model/se3.hpp>
#include <cdcr/model/unit_quaternion.hpp>

namespace cdcr::cli {

// Largest |R^T R - I| entry accepted for a rotation read from --pose. The
// full-precision numbers of `fk --json` pass with a wide margin; a matrix
// rounded to six decimals may not, and is better given as a quaternion.
inline constexpr double kRotationOrthonormalityTolerance = 1e-6;

// Three finite values X,Y,Z in mm.
model::Vec3<double> position_from_values(const std::vector<double>& values);

// QW,QX,QY,QZ (Hamilton convention, scalar first); normalised when within
// model::kQuaternionNormTolerance of unit norm, otherwise an InputError.
model::Mat3<double> rotation_from_quaternion(const std::vector<double>& values);

// 12 or 16 row-major values of [R p; 0 0 0 1]. The rotation must be
// orthonormal with determinant +1 within kRotationOrthonormalityTolerance; it
// is then projected exactly onto SO(3), so the solver is not asked to reach a
// matrix that no rotation equals.
model::Pose<double> pose_from_row_major(const std::vector<double>& values);

}  // namespace cdcr::cli
