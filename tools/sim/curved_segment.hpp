#pragma once
// The shape of one segment whose curvature varies linearly along the
// backbone:
//   kappa(s) = kappa_mean (1 + c (2 s / L - 1)),  s in [0, L],
// bent in the plane of the bend vector b = theta (cos alpha, sin alpha) with
// kappa_mean = theta / L. The tangent turns by phi(s) = theta g(s),
//   g(s) = (s + c (s^2 / L - s)) / L,   g(L) = 1,
// so the end rotation is the arc's, Rot(omega, theta) with
// omega = (-sin alpha, cos alpha, 0), while the position is the integral of
// the tangent, which has no elementary closed form and is evaluated by
// Gauss-Legendre quadrature:
//   p(s) = (u I1, w I1, I2),  I1 = int_0^s g sinc(theta g),  I2 = int_0^s cos(theta g).
// Written in b = (u, w) it has no 1/theta, so the straight segment is exact.
// With c = 0 it is the constant-curvature arc (model::segment_pose), which
// the tests use to check the quadrature.

#include <cdcr/model/se3.hpp>
#include <cdcr/model/types.hpp>

namespace cdcr::sim {

// Pose at arc length fraction * L in the segment's base frame
// (fraction in [0, 1]; 1 is the end disk).
model::Pose<double> curved_segment_pose(const model::Vec2<double>& bend, double backbone_length_mm,
                                        double curvature_gradient, double fraction = 1.0);

}  // namespace cdcr::sim
