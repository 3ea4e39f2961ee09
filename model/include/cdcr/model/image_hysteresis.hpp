#pragma once
// The hysteresis block of a parsed image (flash image v2.2) as the model
// hysteresis.hpp runs: a copy of its widths, weights and homing lags in the
// caller's precision. parse_image() has validated the block by the rules of
// check_hysteresis (and the width bound), so the model it gives is usable.

#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/hysteresis.hpp"

namespace cdcr::model {

// True and `model` filled when the image carries a hysteresis block; false
// and `model` emptied when it does not.
template <typename S>
bool hysteresis_from_image(const ImageView& image, HysteresisModel<S>& model) {
  model = HysteresisModel<S>{};
  if (image.hysteresis_cables <= 0 || image.hysteresis_widths == nullptr) return false;
  model.cables = image.hysteresis_cables;
  model.operators = image.hysteresis_operators;
  for (int c = 0; c < model.cables; ++c) {
    for (int k = 0; k < model.operators; ++k) {
      const int i = c * model.operators + k;
      model.widths_mm[c][k] = S(image.hysteresis_widths[i]);
      model.weights[c][k] = S(image.hysteresis_weights[i]);
      model.homing_lag_mm[c][k] = S(image.hysteresis_homing_lags[i]);
    }
  }
  return true;
}

}  // namespace cdcr::model
