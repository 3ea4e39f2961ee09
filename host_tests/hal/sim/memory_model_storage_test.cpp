// The simulated model region: the image's bytes, aligned as a flash section.
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/sim/memory_model_storage.hpp>

namespace cdcr::sim {
namespace {

TEST(MemoryModelStorage, HoldsTheBytesEightByteAligned) {
  const std::vector<std::uint8_t> bytes = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
  const MemoryModelStorage storage(bytes);
  const hal::MemoryRegion region = storage.model_region();
  ASSERT_EQ(region.size_bytes, bytes.size());
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(region.data) % 8, 0u);
  EXPECT_EQ(std::vector<std::uint8_t>(region.data, region.data + region.size_bytes), bytes);
}

TEST(MemoryModelStorage, EmptyIsNoRegion) {
  MemoryModelStorage storage;
  EXPECT_EQ(storage.model_region().size_bytes, 0u);
  storage.assign({1, 2, 3});
  EXPECT_EQ(storage.model_region().size_bytes, 3u);
  storage.assign({});
  EXPECT_EQ(storage.model_region().size_bytes, 0u);
}

}  // namespace
}  // namespace cdcr::sim
