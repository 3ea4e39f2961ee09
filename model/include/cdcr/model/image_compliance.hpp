#pragma once
// The compliance block of a parsed image (flash image v2.3) as the model
// payload_compliance.hpp runs: a copy in the caller's precision. parse_image()
// has validated the block (finite, ratios above zero, unloaded mass not
// below zero, a softening that keeps the compliance positive), so the model
// it gives is usable.

#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/payload_compliance.hpp"

namespace cdcr::model {

// True and `compliance` filled when the image carries a compliance block of
// at most Max segments; false and `compliance` emptied otherwise.
template <typename S, int Max>
bool compliance_from_image(const ImageView& image, PayloadCompliance<S, Max>& compliance) {
  compliance = PayloadCompliance<S, Max>{};
  if (image.compliance_segments <= 0 || image.compliance_segments > Max || image.compliance_ratios == nullptr) {
    return false;
  }
  compliance.segments = image.compliance_segments;
  for (int k = 0; k < 3; ++k) compliance.weighted_gravity[k] = S(image.compliance_weighted_gravity[k]);
  for (int i = 0; i < compliance.segments; ++i) compliance.ratio[i] = S(image.compliance_ratios[i]);
  compliance.softening_per_rad = S(*image.compliance_softening);
  compliance.unloaded_mass_kg = S(*image.compliance_unloaded_mass);
  return true;
}

}  // namespace cdcr::model
