#include "cli/drives_config.hpp"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli/cli_errors.hpp"

namespace cdcr::cli {

namespace {

using nlohmann::json;
namespace canopen = firmware::canopen;

[[noreturn]] void refuse(const std::string& what) { throw InputError("drives configuration: " + what); }

double number(const json& object, const char* key, double fallback, double low, double high,
              const std::string& where) {
  if (!object.contains(key)) return fallback;
  const json& value = object.at(key);
  if (!value.is_number()) refuse(where + key + " is not a number");
  const double x = value.get<double>();
  if (!(x >= low && x <= high)) {
    std::ostringstream text;
    text << where << key << " = " << x << " is outside [" << low << ", " << high << "]";
    refuse(text.str());
  }
  return x;
}

double whole(const json& object, const char* key, double fallback, double low, double high,
             const std::string& where) {
  const double x = number(object, key, fallback, low, high, where);
  if (x != std::floor(x)) refuse(where + key + " is not a whole number");
  return x;
}

void only_keys(const json& object, const std::set<std::string>& keys, const std::string& where) {
  for (const auto& item : object.items())
    if (!keys.count(item.key())) refuse(where + "unknown field \"" + item.key() + "\"");
}

}  // namespace

DrivesConfig parse_drives_config(const std::string& text, std::uint32_t cycle_period_us) {
  json root;
  try {
    root = json::parse(text);
  } catch (const json::parse_error& e) {
    refuse(std::string("not JSON: ") + e.what());
  }
  if (!root.is_object()) refuse("the top level is not an object");
  only_keys(root,
            {"buses", "heartbeat_ms", "heartbeat_periods_lost", "stale_cycles", "sync_window_us", "boot_timeout_ms",
             "sdo_timeout_ms", "enable_timeout_ms", "max_speed_mm_per_s", "drives"},
            "");
  DrivesConfig config;
  if (!root.contains("buses") || !root["buses"].is_array() || root["buses"].empty())
    refuse("\"buses\" must list at least one interface");
  if (root["buses"].size() > std::size_t(canopen::kMaxDriveBuses))
    refuse("more than " + std::to_string(canopen::kMaxDriveBuses) + " buses");
  for (const json& bus : root["buses"]) {
    if (!bus.is_string() || bus.get<std::string>().empty()) refuse("buses: an entry is not an interface name");
    config.buses.push_back(bus.get<std::string>());
  }
  canopen::DriveManagerConfig& manager = config.manager;
  manager.bus_count = int(config.buses.size());
  manager.timing.cycle_period_us = cycle_period_us;
  manager.timing.heartbeat_ms = std::uint16_t(whole(root, "heartbeat_ms", 50, 1, 65535, ""));
  manager.heartbeat_periods_lost = std::uint32_t(whole(root, "heartbeat_periods_lost", 3, 1, 100, ""));
  manager.stale_cycles = std::uint32_t(whole(root, "stale_cycles", 10, 1, 100000, ""));
  manager.timing.sync_window_us =
      std::uint32_t(whole(root, "sync_window_us", std::min<double>(500, cycle_period_us), 0, cycle_period_us, ""));
  manager.boot_timeout_ms = std::uint32_t(whole(root, "boot_timeout_ms", 2000, 1, 600000, ""));
  manager.sdo_timeout_ms = std::uint32_t(whole(root, "sdo_timeout_ms", 100, 1, 60000, ""));
  manager.enable_timeout_ms = std::uint32_t(whole(root, "enable_timeout_ms", 1000, 1, 600000, ""));
  manager.max_speed_mm_per_s = number(root, "max_speed_mm_per_s", 20, 1e-3, 1e4, "");

  if (!root.contains("drives") || !root["drives"].is_array() || root["drives"].empty())
    refuse("\"drives\" must list one drive per cable");
  const json& drives = root["drives"];
  if (drives.size() > std::size_t(canopen::kMaxDrives))
    refuse("more than " + std::to_string(canopen::kMaxDrives) + " drives");
  manager.drive_count = int(drives.size());
  std::vector<bool> seen(drives.size(), false);
  for (std::size_t k = 0; k < drives.size(); ++k) {
    const std::string where = "drives[" + std::to_string(k) + "].";
    const json& drive = drives[k];
    if (!drive.is_object()) refuse(where.substr(0, where.size() - 1) + " is not an object");
    only_keys(drive, {"cable", "bus", "node", "counts_per_mm", "direction", "homing_offset_mm"}, where);
    for (const char* key : {"cable", "node", "counts_per_mm", "homing_offset_mm"})
      if (!drive.contains(key)) refuse(where + key + " is missing");
    const int cable = int(whole(drive, "cable", 0, 0, double(drives.size() - 1), where));
    if (seen[cable]) refuse(where + "cable " + std::to_string(cable) + " has a drive already");
    seen[cable] = true;
    canopen::DriveChannel& channel = manager.drives[cable];
    channel.bus = std::uint8_t(whole(drive, "bus", 0, 0, double(config.buses.size() - 1), where));
    channel.node = canopen::NodeId(whole(drive, "node", 0, canopen::kMinNodeId, canopen::kMaxNodeId, where));
    const double counts = number(drive, "counts_per_mm", 0, 1e-3, 1e6, where);
    const double direction = whole(drive, "direction", 1, -1, 1, where);
    if (direction == 0) refuse(where + "direction must be 1 or -1");
    channel.counts_per_mm = counts * direction;
    channel.offset_mm = number(drive, "homing_offset_mm", 0, -1e4, 1e4, where);
  }
  const canopen::DriveConfigStatus status = canopen::validate(manager);
  if (status != canopen::DriveConfigStatus::ok) refuse(canopen::to_string(status));
  return config;
}

DrivesConfig read_drives_config(const std::string& path, std::uint32_t cycle_period_us) {
  std::ifstream file(path);
  if (!file) throw InputError("drives configuration: cannot read " + path);
  std::ostringstream text;
  text << file.rdbuf();
  return parse_drives_config(text.str(), cycle_period_us);
}

}  // namespace cdcr::cli
