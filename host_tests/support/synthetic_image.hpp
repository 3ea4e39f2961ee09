#pragma once
// A synthetic model (synthetic_trained_model.hpp) as the firmware meets it:
// the image the exporter writes, and that image parsed.

#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/flash_image.hpp"
#include "export/image_writer.hpp"
#include "synthetic_trained_model.hpp"

namespace cdcr::test_support {

struct SyntheticImage {
  training::TrainedModel trained;
  std::vector<std::uint8_t> bytes;
  model::ImageView view{};  // into bytes
};

// Fails the test if the image does not parse within `capacity`.
inline SyntheticImage synthetic_image(const SyntheticModelOptions& options,
                                      const model::ImageCapacity& capacity = model::ImageCapacity{}) {
  SyntheticImage image;
  image.trained = synthetic_trained_model(options);
  image.bytes = exporting::write_image(image.trained);
  EXPECT_EQ(model::parse_image(image.bytes.data(), image.bytes.size(), image.view, capacity), model::ImageStatus::ok);
  return image;
}

}  // namespace cdcr::test_support
