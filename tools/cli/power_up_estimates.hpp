#pragma once
// The board's estimates over a motion sequence that starts at power-up, not
// at home: the hysteresis state unknown (model::reset_unknown), moved by each
// row's commanded lengths through the runtime's own tracker
// (firmware::HysteresisTracker), the pose estimated on the effective lengths
// and the r95 radii widened while the state is unknown, in the order the
// runtime's cycle takes these steps. `cdcr eval --from-power-up` uses it for
// the rows before the data's second session.

#include <vector>

#include <Eigen/Core>

#include "cdcr/model/flash_image.hpp"
#include "train/evaluation.hpp"

namespace cdcr::cli {

struct PowerUpEstimates {
  std::vector<training::FirmwareEstimate> estimates;  // one per row
  // The rows estimated while the state was still unknown (the first ones).
  int unknown_rows = 0;
};

// Throws std::invalid_argument when the image has no hysteresis block, takes
// a payload input, or a row's lengths have no pose.
PowerUpEstimates estimates_from_power_up(const model::ImageView& image, const Eigen::MatrixXd& cables_mm);

}  // namespace cdcr::cli
