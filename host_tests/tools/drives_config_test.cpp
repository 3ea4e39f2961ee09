// The CiA 402 drives' configuration file (cli/drives_config.hpp): a file as
// an integrator writes it, read into the manager's configuration, and each
// way a file can be wrong refused with one line naming the field.

#include <string>

#include <gtest/gtest.h>

#include "cli/cli_errors.hpp"
#include "cli/drives_config.hpp"

namespace cdcr::cli {
namespace {

const char* kTwoDrives = R"({
  "buses": ["can1", "can2"],
  "heartbeat_ms": 20,
  "drives": [
    {"cable": 1, "bus": 1, "node": 3, "counts_per_mm": 4096, "direction": -1, "homing_offset_mm": 118.5},
    {"cable": 0, "bus": 0, "node": 3, "counts_per_mm": 2000, "homing_offset_mm": 120}
  ]
})";

TEST(DrivesConfig, ReadsEveryField) {
  const DrivesConfig config = parse_drives_config(kTwoDrives, 2000);
  ASSERT_EQ(config.buses.size(), 2u);
  EXPECT_EQ(config.buses[1], "can2");
  const auto& manager = config.manager;
  EXPECT_EQ(manager.drive_count, 2);
  EXPECT_EQ(manager.bus_count, 2);
  EXPECT_EQ(manager.timing.cycle_period_us, 2000u);
  EXPECT_EQ(manager.timing.heartbeat_ms, 20);
  EXPECT_EQ(manager.timing.sync_window_us, 500u);  // the default
  EXPECT_EQ(manager.stale_cycles, 10u);
  // Ordered by cable, not by their place in the file.
  EXPECT_EQ(manager.drives[0].bus, 0);
  EXPECT_DOUBLE_EQ(manager.drives[0].counts_per_mm, 2000.0);
  EXPECT_DOUBLE_EQ(manager.drives[0].offset_mm, 120.0);
  EXPECT_EQ(manager.drives[1].bus, 1);
  EXPECT_EQ(manager.drives[1].node, 3);
  EXPECT_DOUBLE_EQ(manager.drives[1].counts_per_mm, -4096.0);
  EXPECT_DOUBLE_EQ(manager.drives[1].offset_mm, 118.5);
}

std::string refusal(const std::string& text) {
  try {
    parse_drives_config(text, 1000);
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

std::string with(const std::string& from, const std::string& to) {
  std::string text = kTwoDrives;
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(DrivesConfig, RefusesWithTheField) {
  EXPECT_EQ(refusal("{"), refusal("{"));
  EXPECT_NE(refusal("{").find("drives configuration: not JSON"), std::string::npos);
  EXPECT_EQ(refusal(with(R"("buses": ["can1", "can2"],)", R"("buses": [],)")),
            "drives configuration: \"buses\" must list at least one interface");
  EXPECT_EQ(refusal(with(R"("node": 3, "counts_per_mm": 4096)", R"("node": 128, "counts_per_mm": 4096)")),
            "drives configuration: drives[0].node = 128 is outside [1, 127]");
  EXPECT_EQ(refusal(with(R"("cable": 1,)", R"("cable": 0,)")),
            "drives configuration: drives[1].cable 0 has a drive already");
  EXPECT_EQ(refusal(with(R"("cable": 1,)", R"("cable": 2,)")),
            "drives configuration: drives[0].cable = 2 is outside [0, 1]");
  EXPECT_EQ(refusal(with(R"("bus": 1,)", R"("bus": 2,)")),
            "drives configuration: drives[0].bus = 2 is outside [0, 1]");
  EXPECT_EQ(refusal(with(R"("direction": -1,)", R"("direction": 0,)")),
            "drives configuration: drives[0].direction must be 1 or -1");
  EXPECT_EQ(refusal(with(R"("counts_per_mm": 2000,)", R"("counts_per_mm": 0,)")),
            "drives configuration: drives[1].counts_per_mm = 0 is outside [0.001, 1e+06]");
  EXPECT_EQ(refusal(with(R"(, "homing_offset_mm": 120})", "}")),
            "drives configuration: drives[1].homing_offset_mm is missing");
  EXPECT_EQ(refusal(with(R"("heartbeat_ms": 20,)", R"("heartbeat_ms": 20, "heartbeat": 1,)")),
            "drives configuration: unknown field \"heartbeat\"");
  EXPECT_EQ(refusal(with(R"("heartbeat_ms": 20,)", R"("heartbeat_ms": 2.5,)")),
            "drives configuration: heartbeat_ms is not a whole number");
  EXPECT_EQ(refusal(with(R"("heartbeat_ms": 20,)", R"("sync_window_us": 1500,)")),
            "drives configuration: sync_window_us = 1500 is outside [0, 1000]");
  EXPECT_EQ(refusal(with(R"("bus": 1, "node": 3,)", R"("bus": 0, "node": 3,)")),
            "drives configuration: two cables on one node id of a bus");
  EXPECT_EQ(refusal(with(R"("node": 3, "counts_per_mm": 2000)", R"("node": "3", "counts_per_mm": 2000)")),
            "drives configuration: drives[1].node is not a number");
}

TEST(DrivesConfig, MissingFile) {
  EXPECT_THROW(read_drives_config("/nonexistent/drives.json", 1000), InputError);
}

}  // namespace
}  // namespace cdcr::cli
