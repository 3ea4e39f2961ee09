#pragma once
// Serialises a trained model into flash image format v2
// (model/flash-image-v2.md); it writes no other version. The parser in the model library is the
// specification's other half; every image written here parses there.

#include <cstdint>
#include <vector>

#include "trained_model/trained_model.hpp"

namespace cdcr::exporting {

// Throws std::invalid_argument if the model cannot be represented (wrong
// dims, non-finite values after conversion to float32, or anything else
// parse_image() would refuse, such as a non-positive scale, an inverted input
// range, or an exact model whose fitted_rows is not its number of points).
std::vector<std::uint8_t> write_image(const training::TrainedModel& model);

}  // namespace cdcr::exporting
