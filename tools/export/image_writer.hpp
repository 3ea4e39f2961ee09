#pragma once
// Serialises a trained model into flash image format v1
// (model/flash-image-v1.md). The parser in the model library is the
// specification's other half; every image written here parses there.

#include <cstdint>
#include <vector>

#include "train/trained_model.hpp"

namespace cdcr::exporting {

// Throws std::invalid_argument if the model cannot be represented (wrong
// dims, non-finite values after conversion to float32, or anything else
// parse_image() would refuse, such as a non-positive scale).
std::vector<std::uint8_t> write_image(const training::TrainedModel& model);

}  // namespace cdcr::exporting
