#pragma once
// What the flash image tests share to damage a valid image by hand: typed
// reads and writes at a byte offset, the trailer recomputed after an edit (so
// the edit reaches the checks behind the CRC), and a sink that keeps every
// finding of a reporting parse.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/flash_image.hpp"

#include "../support/reference_crc32.hpp"

namespace cdcr::test_support {

using Bytes = std::vector<std::uint8_t>;

template <typename T>
T get(const Bytes& image, std::size_t offset) {
  T value;
  std::memcpy(&value, image.data() + offset, sizeof(T));
  return value;
}

template <typename T>
void put(Bytes& image, std::size_t offset, T value) {
  std::memcpy(image.data() + offset, &value, sizeof(T));
}

// Recomputes the trailer for the total_size the header declares.
inline void reseal(Bytes& image) {
  const auto total = get<std::uint32_t>(image, model::image_field::total_size.offset);
  put<std::uint32_t>(image, total - model::kImageTrailerSize,
                     reference_crc32(image.data(), total - model::kImageTrailerSize));
}

// Every finding of a reporting parse.
class Findings : public model::ImageCheckSink {
 public:
  void on_finding(const model::ImageFinding& finding) override { all.push_back(finding); }

  const model::ImageFinding* first_failure() const {
    for (const model::ImageFinding& f : all) {
      if (!f.passed) return &f;
    }
    return nullptr;
  }
  bool failed(model::ImageCheckId check) const {
    return std::any_of(all.begin(), all.end(),
                       [check](const model::ImageFinding& f) { return f.check == check && !f.passed; });
  }
  const model::ImageFinding* failure_of(const char* field) const {
    for (const model::ImageFinding& f : all) {
      if (!f.passed && std::string(f.field) == field) return &f;
    }
    return nullptr;
  }

  // Whether `check` passed once for all `count` values of a block.
  bool passed_once_for(model::ImageCheckId check, std::uint32_t count) const {
    return std::any_of(all.begin(), all.end(), [&](const model::ImageFinding& f) {
      return f.check == check && f.passed && f.count == count;
    });
  }

  std::vector<model::ImageFinding> all;
};

// The verdict of all three modes (stopping, reporting, scanned), which must
// agree; the first failed finding of the reporting one in `first` (empty
// field when none failed).
inline model::ImageStatus parse_all_ways(const Bytes& image, model::ImageFinding& first) {
  model::ImageView view{};
  const model::ImageStatus status = model::parse_image(image.data(), image.size(), view);
  Findings findings;
  EXPECT_EQ(model::parse_image(image.data(), image.size(), view, model::ImageCapacity{}, &findings), status);
  model::ImageScan scan;
  scan.begin(image.data(), image.size());
  while (!scan.step(64)) {
  }
  EXPECT_EQ(model::parse_image(image.data(), image.size(), view, model::ImageCapacity{}, scan), status);
  first = model::ImageFinding{};
  first.field = "";
  if (const model::ImageFinding* f = findings.first_failure(); f != nullptr) first = *f;
  return status;
}

}  // namespace cdcr::test_support
