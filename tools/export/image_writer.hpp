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
// A model with a hysteresis model (TrainedModel::hysteresis) is written as
// a v2.2 image with the hysteresis block, one with a compliance model
// (TrainedModel::compliance, a payload model only) as a v2.3 image with the
// compliance block; one with neither, as a v2.1 image.
std::vector<std::uint8_t> write_image(const training::TrainedModel& model);

// `image` (a valid v2 image without a hysteresis block) with `hysteresis`
// added: the same model, written as v2.2. Throws std::invalid_argument as
// write_image does.
std::vector<std::uint8_t> with_hysteresis_block(const std::vector<std::uint8_t>& image,
                                                const model::HysteresisModel<double>& hysteresis);

// `image` (a valid v2 image with the payload input and without a hysteresis
// or compliance block) with `compliance` added: the same model, written as
// v2.3. Throws std::invalid_argument as write_image does.
std::vector<std::uint8_t> with_compliance_block(const std::vector<std::uint8_t>& image,
                                                const model::PayloadCompliance<double>& compliance);

}  // namespace cdcr::exporting
