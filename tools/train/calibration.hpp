#pragma once
// The nominal model's geometry identified from the measured poses before the
// GP sees them, so that the GP learns only what the geometry cannot explain.
//
// Identified per segment: the backbone length L and the anchor radius r.
// Through the cable-to-joint map theta = f(cable differences) / r, r is the
// segment's bending gain: cable stretch under load, for example, makes a
// segment bend less than commanded, which a larger effective r describes.
// Both live in the image's geometry block, so the firmware and every tool
// run the calibrated model with the kinematics code they already share.
//
// Levenberg-Marquardt (Eigen's) on the tip error twists of all rows, the
// rotation part weighted by the robot's length so that a radian of tip
// rotation counts like the arc it sweeps.

#include "cdcr/model/geometry.hpp"
#include "evaluation.hpp"
#include "training_set.hpp"

namespace cdcr::training {

struct Calibration {
  model::RobotGeometry<double> geometry;
  MeanErrors before;  // the design geometry's nominal model on the rows
  MeanErrors after;   // the calibrated one's
  int evaluations = 0;
};

// Throws std::invalid_argument when the rows cannot identify the geometry
// (fewer rows than twice the parameters) or the search leaves the plausible
// range (each value within a factor of two of the design's).
Calibration calibrate_geometry(const TrainingSet& set, const model::RobotGeometry<double>& design);

}  // namespace cdcr::training
