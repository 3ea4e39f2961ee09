// The C API (cdcr/cdcr.h): the runtime behind the HAL of the caller's callbacks
// (hal/callbacks), in the caller's storage. Cable lengths, targets, the payload
// and homing are queued and handed to the runtime's direct inputs at the next
// step, ahead of the bus's frames, in the values the protocol's frames would
// carry (the same checks as from a bus); its own frames go to can_send. With
// CiA 402 drives (cdcr_config.cia402_drives) the cable lengths come from them
// instead, over the drives_can callbacks.

#include "cdcr/cdcr.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <new>

#include "cdcr/callbacks/callback_hal.hpp"
#include "cdcr/firmware/canopen/cia402_drives.hpp"
#include "cdcr/firmware/runtime.hpp"
#include "cdcr/hal/shifted_can_bus.hpp"
#include "cdcr/model/unit_quaternion.hpp"

namespace cdcr::firmware {
namespace {

// Inputs queued between two steps, in the frames that would carry them: a cable
// frame per segment twice over, two targets (three frames each), payload, homing.
constexpr int kInputQueueDepth = 2 * kMaxSegments + 6 + 2;
constexpr std::uint32_t kInitializedMagic = 0x43444352u;  // "CDCR"

double transmitted(const protocol::SignalSpec& signal, float value) { return protocol::as_transmitted(signal, value); }

// The inputs given since the last step, oldest first, as the caller gave
// them (checked); each reaches the runtime as its frames would have.
class InputQueue final : public CycleInputs {
 public:
  bool has_room(int frames) const { return frames_ + frames <= kInputQueueDepth; }
  // A segment of three cables: the fourth is not available, as on the bus.
  void push_cables(int segment, const float* lengths_mm, int cables) {
    Input& input = push(Kind::cables, 1);
    input.segment = static_cast<std::uint8_t>(segment);
    for (int k = 0; k < 4; ++k) input.values[k] = k < cables ? lengths_mm[k] : std::numeric_limits<float>::quiet_NaN();
  }
  void push_target(const cdcr_target& target) {
    const bool pose = target.mode == CDCR_TARGET_POSE;
    Input& input = push(Kind::target, pose ? 3 : 2);
    input.flags = static_cast<std::uint8_t>((pose ? kPose : 0) | (target.tracking != 0 ? kTracking : 0) |
                                            (target.refuse_extrapolating != 0 ? kRefuse : 0));
    input.sequence = target.sequence;
    for (int i = 0; i < 3; ++i) input.values[i] = target.position_mm[i];
    for (int i = 0; i < 4; ++i) input.values[3 + i] = target.quaternion[i];
  }
  void push_payload(float payload_kg) { push(Kind::payload, 1).values[0] = payload_kg; }
  void push_homing() { push(Kind::homing, 1); }

  int deliver(Runtime& runtime) override {
    for (int i = 0; i < count_; ++i) {
      const Input& input = inputs_[i];
      if (input.kind == Kind::cables) {
        Scalar lengths_mm[4];
        for (int k = 0; k < 4; ++k) {
          lengths_mm[k] = std::isnan(input.values[k]) ? input.values[k]
                                                      : Scalar(protocol::cable_length_as_transmitted(input.values[k]));
        }
        runtime.set_cable_lengths(input.segment, lengths_mm);
      } else if (input.kind == Kind::target) {
        runtime.set_target(target_request(input));
      } else if (input.kind == Kind::homing) {
        runtime.set_homed();
      } else {
        runtime.set_payload_kg(Scalar(transmitted(protocol::payload::kPayload, input.values[0])));
      }
    }
    const int frames = frames_;
    count_ = frames_ = 0;
    return frames;
  }

 private:
  enum class Kind : std::uint8_t { cables, target, payload, homing };
  enum Flags : std::uint8_t { kPose = 1, kTracking = 2, kRefuse = 4 };
  // Small: the queue lives in cdcr_runtime's storage. A target's values are
  // its position and quaternion, a cable input's the segment's four lengths.
  struct Input {
    Kind kind = Kind::cables;
    std::uint8_t segment = 0, flags = 0, sequence = 0;
    float values[7] = {};
  };

  Input& push(Kind kind, int frames) {
    frames_ += frames;
    inputs_[count_].kind = kind;
    return inputs_[count_++];
  }

  static TargetRequest target_request(const Input& in) {
    TargetRequest out;
    out.position_mm[0] = transmitted(protocol::position_xy::kX, in.values[0]);
    out.position_mm[1] = transmitted(protocol::position_xy::kY, in.values[1]);
    out.position_mm[2] = transmitted(protocol::target_position_z::kZ, in.values[2]);
    out.mode = (in.flags & kPose) != 0 ? protocol::TargetMode::pose : protocol::TargetMode::position;
    if (out.mode == protocol::TargetMode::pose) {
      out.quaternion[0] = transmitted(protocol::quaternion::kQw, in.values[3]);
      out.quaternion[1] = transmitted(protocol::quaternion::kQx, in.values[4]);
      out.quaternion[2] = transmitted(protocol::quaternion::kQy, in.values[5]);
      out.quaternion[3] = transmitted(protocol::quaternion::kQz, in.values[6]);
    }
    out.tracking = (in.flags & kTracking) != 0;
    out.refuse_extrapolating = (in.flags & kRefuse) != 0;
    out.sequence = in.sequence;
    return out;
  }

  Input inputs_[kInputQueueDepth] = {};
  int count_ = 0;
  int frames_ = 0;
};

// The drives' configuration of the C API's, with its defaults; false if
// validate() refuses it.
bool drives_config_from(const cdcr_cia402_config& in, std::int64_t period_ns, canopen::DriveManagerConfig& out) {
  if (in.drive_count < 1 || in.drive_count > kMaxDrives || period_ns <= 0 || period_ns % 1000 != 0 ||
      period_ns / 1000 > std::numeric_limits<std::uint32_t>::max() || in.heartbeat_ms > 0xFFFF)
    return false;
  out = canopen::DriveManagerConfig{};
  out.drive_count = in.drive_count;
  out.bus_count = in.bus_count;
  for (int i = 0; i < in.drive_count; ++i) {
    const cdcr_cia402_drive& d = in.drives[i];
    if (d.bus < 0 || d.bus >= kMaxDriveBuses || d.node < 1 || d.node > 127) return false;
    out.drives[i] = {std::uint8_t(d.bus), canopen::NodeId(d.node), double(d.counts_per_mm), double(d.homing_offset_mm)};
  }
  const auto or_default = [](std::uint32_t value, std::uint32_t fallback) { return value != 0 ? value : fallback; };
  out.timing.cycle_period_us = std::uint32_t(period_ns / 1000);
  out.timing.sync_window_us = or_default(in.sync_window_us, out.timing.cycle_period_us / 2);
  out.timing.heartbeat_ms = std::uint16_t(or_default(in.heartbeat_ms, out.timing.heartbeat_ms));
  out.heartbeat_periods_lost = or_default(in.heartbeat_periods_lost, out.heartbeat_periods_lost);
  out.stale_cycles = or_default(in.stale_cycles, out.stale_cycles);
  out.boot_timeout_ms = or_default(in.boot_timeout_ms, out.boot_timeout_ms);
  out.sdo_timeout_ms = or_default(in.sdo_timeout_ms, out.sdo_timeout_ms);
  out.enable_timeout_ms = or_default(in.enable_timeout_ms, out.enable_timeout_ms);
  if (in.max_speed_mm_per_s != 0) out.max_speed_mm_per_s = double(in.max_speed_mm_per_s);
  return canopen::validate(out) == canopen::DriveConfigStatus::ok;
}

// Everything cdcr_runtime holds. The HAL comes before the runtime, which
// keeps references to its parts.
struct CRuntime {
  CRuntime(const cdcr_config& config, const Geometry& fallback, std::uint32_t id_base,
           const canopen::DriveManagerConfig* drives_config)
      : hal(config.callbacks, config.model_image, config.model_image_size),
        can(hal.hal().can, protocol::id_offset(id_base)),
        drives_buses{{hal.callbacks(), 0}, {hal.callbacks(), 1}, {hal.callbacks(), 2}, {hal.callbacks(), 3}},
        drives(drives_config != nullptr ? *drives_config : canopen::DriveManagerConfig{}, bus_pointers()),
        runtime(with_can(hal.hal(), can, drives_config != nullptr ? &drives : nullptr), fallback) {}

  static hal::Hal with_can(const hal::Hal& h, hal::CanBus& bus, hal::Drives* drives) {
    hal::Hal out{h.clock, h.timer, bus, h.model_storage, h.console, h.flash};
    out.drives = drives;
    return out;
  }
  using BusPointers = hal::CanBus* const[kMaxDriveBuses];
  const BusPointers& bus_pointers() {
    for (int b = 0; b < kMaxDriveBuses; ++b) drives_bus_pointers[b] = &drives_buses[b];
    return drives_bus_pointers;
  }

  std::uint32_t magic = 0;
  callbacks::CallbackHal hal;
  hal::ShiftedCanBus can;  // the callbacks' bus at the identifier base
  callbacks::CallbackDrivesBus drives_buses[kMaxDriveBuses];
  hal::CanBus* drives_bus_pointers[kMaxDriveBuses] = {};
  canopen::Cia402Drives drives;  // used only with cia402_drives
  InputQueue inputs;
  Runtime runtime;
};

// cdcr_runtime's storage holds a CRuntime at the first suitably aligned
// address; the header's size leaves room for that.
constexpr std::size_t kStorageNeeded = sizeof(CRuntime) + alignof(CRuntime) - 1;
static_assert(kStorageNeeded <= CDCR_RUNTIME_STORAGE_BYTES,
              "CDCR_RUNTIME_STORAGE_BYTES in cdcr/cdcr.h is too small for this target");

void* aligned_storage(const cdcr_runtime* runtime) {
  auto address = reinterpret_cast<std::uintptr_t>(runtime->storage.bytes);
  address = (address + alignof(CRuntime) - 1) & ~std::uintptr_t(alignof(CRuntime) - 1);
  return reinterpret_cast<void*>(address);
}

CRuntime* initialized(const cdcr_runtime* runtime) {
  if (runtime == nullptr) return nullptr;
  auto* c = static_cast<CRuntime*>(aligned_storage(runtime));
  return c->magic == kInitializedMagic ? c : nullptr;
}

cdcr_result check(const cdcr_runtime* runtime, CRuntime*& c) {
  if (runtime == nullptr) return CDCR_ERROR_NULL_ARGUMENT;
  c = initialized(runtime);
  return c != nullptr ? CDCR_OK : CDCR_ERROR_NOT_INITIALIZED;
}

bool geometry_from_config(const cdcr_geometry& in, Geometry& out) {
  if (in.segment_count == 0 && in.backbone_length_mm == 0 && in.anchor_radius_mm == 0 && in.theta_max_rad == 0) {
    out = Geometry::prototype();
    return true;
  }
  if (in.cables_per_segment != 0 && in.cables_per_segment != 3 && in.cables_per_segment != 4) return false;
  out = Geometry::uniform(in.segment_count, in.backbone_length_mm, in.anchor_radius_mm, in.theta_max_rad);
  if (in.cables_per_segment == 3) {
    for (int i = 0; i < out.segment_count; ++i) out.segments[i].cables = model::CableLayout<Scalar>::evenly_spaced(3);
  }
  return out.validate() == model::Status::ok;
}

}  // namespace
}  // namespace cdcr::firmware

using cdcr::firmware::CRuntime;
namespace firmware = cdcr::firmware;
namespace protocol = cdcr::firmware::protocol;

static_assert(int(CDCR_STATE_FAULT) == int(firmware::RuntimeState::fault), "states as in fault.hpp");
static_assert(int(CDCR_FAULT_HOMING_MALFORMED) == int(firmware::FaultCode::homing_malformed), "faults as fault.hpp");
static_assert(int(CDCR_FAULT_DRIVE_REFUSED) == int(firmware::FaultCode::drive_refused), "faults as fault.hpp");
static_assert(int(CDCR_FAULT_DRIVES_COMMAND_MALFORMED) == int(firmware::FaultCode::drives_command_malformed),
              "faults as fault.hpp");
static_assert(int(CDCR_IK_IN_PROGRESS) == int(protocol::IkOutcome::in_progress), "outcomes as in messages.hpp");
static_assert(int(CDCR_IK_REFUSED_EXTRAPOLATING) == int(protocol::IkOutcome::refused_extrapolating), "outcomes");
static_assert(int(CDCR_TARGET_POSE) == int(protocol::TargetMode::pose), "modes as in messages.hpp");
static_assert(CDCR_MAX_SEGMENTS == firmware::kMaxSegments, "segment capacity as in capacity.hpp");
static_assert(CDCR_MAX_CABLES == firmware::kMaxDrives, "a drive per cable, as in capacity.hpp");
static_assert(CDCR_MAX_DRIVE_BUSES == firmware::kMaxDriveBuses, "drive buses as in capacity.hpp");

extern "C" {

size_t cdcr_runtime_storage_size(void) { return firmware::kStorageNeeded; }

cdcr_result cdcr_init(cdcr_runtime* runtime, const cdcr_config* config) {
  if (runtime == nullptr || config == nullptr) return CDCR_ERROR_NULL_ARGUMENT;
  if (config->model_image == nullptr && config->model_image_size != 0) return CDCR_ERROR_NULL_ARGUMENT;
  if (config->period_ns < 0) return CDCR_ERROR_INVALID_ARGUMENT;
  firmware::Geometry fallback;
  if (!firmware::geometry_from_config(config->fallback_geometry, fallback)) return CDCR_ERROR_INVALID_ARGUMENT;
  const std::uint32_t id_base = config->can_id_base == 0 ? protocol::kDefaultIdBase : config->can_id_base;
  if (!protocol::is_valid_id_base(id_base)) return CDCR_ERROR_INVALID_ARGUMENT;
  firmware::canopen::DriveManagerConfig drives;
  if (config->cia402_drives != nullptr &&
      !firmware::drives_config_from(*config->cia402_drives, config->period_ns, drives))
    return CDCR_ERROR_INVALID_ARGUMENT;
  auto* c = new (firmware::aligned_storage(runtime))
      CRuntime(*config, fallback, id_base, config->cia402_drives != nullptr ? &drives : nullptr);
  c->hal.timer().start(config->period_ns);
  c->runtime.init();
  c->magic = firmware::kInitializedMagic;
  return CDCR_OK;
}

cdcr_result cdcr_step(cdcr_runtime* runtime) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  c->runtime.run_cycle(c->hal.timer().wait_next(), &c->inputs);
  return CDCR_OK;
}

cdcr_result cdcr_set_segment_cable_lengths(cdcr_runtime* runtime, int segment, const float* lengths_mm) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  if (lengths_mm == nullptr) return CDCR_ERROR_NULL_ARGUMENT;
  if (c->runtime.has_drives()) return CDCR_ERROR_NOT_APPLICABLE;
  if (segment < 0 || segment >= c->runtime.geometry().segment_count) return CDCR_ERROR_INVALID_ARGUMENT;
  const int cables = c->runtime.geometry().segments[segment].cables.count;
  for (int k = 0; k < cables; ++k) {
    if (!protocol::cable_length_encodable(lengths_mm[k])) return CDCR_ERROR_OUT_OF_RANGE;
  }
  if (!c->inputs.has_room(1)) return CDCR_ERROR_QUEUE_FULL;
  c->inputs.push_cables(segment, lengths_mm, cables);
  return CDCR_OK;
}

cdcr_result cdcr_get_segment_cables(const cdcr_runtime* runtime, int segment, int* cables) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  if (cables == nullptr) return CDCR_ERROR_NULL_ARGUMENT;
  if (segment < 0 || segment >= c->runtime.geometry().segment_count) return CDCR_ERROR_INVALID_ARGUMENT;
  *cables = c->runtime.geometry().segments[segment].cables.count;
  return CDCR_OK;
}

cdcr_result cdcr_set_cable_lengths(cdcr_runtime* runtime, const float* lengths_mm, size_t count) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  if (lengths_mm == nullptr) return CDCR_ERROR_NULL_ARGUMENT;
  if (c->runtime.has_drives()) return CDCR_ERROR_NOT_APPLICABLE;
  const firmware::Geometry& geometry = c->runtime.geometry();
  const int segments = geometry.segment_count;
  if (count != size_t(geometry.cable_count())) return CDCR_ERROR_INVALID_ARGUMENT;
  // All or nothing: check every value and the room first.
  for (size_t i = 0; i < count; ++i) {
    if (!protocol::cable_length_encodable(lengths_mm[i])) return CDCR_ERROR_OUT_OF_RANGE;
  }
  if (!c->inputs.has_room(segments)) return CDCR_ERROR_QUEUE_FULL;
  for (int s = 0; s < segments; ++s) cdcr_set_segment_cable_lengths(runtime, s, lengths_mm + geometry.first_cable(s));
  return CDCR_OK;
}

cdcr_result cdcr_set_payload(cdcr_runtime* runtime, float payload_kg) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  std::int64_t raw = 0;
  if (!protocol::to_raw_checked(protocol::payload::kPayload, payload_kg, raw)) return CDCR_ERROR_OUT_OF_RANGE;
  if (!c->inputs.has_room(1)) return CDCR_ERROR_QUEUE_FULL;
  c->inputs.push_payload(payload_kg);
  return CDCR_OK;
}

cdcr_result cdcr_homing(cdcr_runtime* runtime) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  return c->inputs.has_room(1) ? (c->inputs.push_homing(), CDCR_OK) : CDCR_ERROR_QUEUE_FULL;
}

cdcr_result cdcr_recover_drives(cdcr_runtime* runtime) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  if (!c->runtime.has_drives()) return CDCR_ERROR_NOT_APPLICABLE;
  c->runtime.recover_drives();
  return CDCR_OK;
}

cdcr_result cdcr_set_target(cdcr_runtime* runtime, const cdcr_target* target) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  if (target == nullptr) return CDCR_ERROR_NULL_ARGUMENT;
  if (target->mode != CDCR_TARGET_POSITION && target->mode != CDCR_TARGET_POSE) return CDCR_ERROR_INVALID_ARGUMENT;
  const bool pose = target->mode == CDCR_TARGET_POSE;
  constexpr double kMaxPositionMm = 21474836.0;
  for (const float p : target->position_mm) {
    if (!std::isfinite(p) || std::fabs(p) > kMaxPositionMm) return CDCR_ERROR_OUT_OF_RANGE;
  }
  if (pose) {
    double norm2 = 0;
    for (const float q : target->quaternion) {
      if (!std::isfinite(q)) return CDCR_ERROR_OUT_OF_RANGE;
      norm2 += double(q) * q;
    }
    if (!cdcr::model::is_unit_quaternion_norm(std::sqrt(norm2))) return CDCR_ERROR_INVALID_ARGUMENT;
  }
  if (!c->inputs.has_room(pose ? 3 : 2)) return CDCR_ERROR_QUEUE_FULL;
  c->inputs.push_target(*target);
  return CDCR_OK;
}

cdcr_result cdcr_get_pose(const cdcr_runtime* runtime, cdcr_pose* pose) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  if (pose == nullptr) return CDCR_ERROR_NULL_ARGUMENT;
  const firmware::Runtime& rt = c->runtime;
  if (!rt.has_pose() || rt.state() == firmware::RuntimeState::fault) return CDCR_ERROR_NO_DATA;
  const firmware::PoseEstimate& estimate = rt.latest_pose();
  *pose = cdcr_pose{};
  for (int i = 0; i < 3; ++i) {
    pose->position_mm[i] = estimate.pose.position_mm[i];
    for (int j = 0; j < 3; ++j) pose->rotation[3 * i + j] = estimate.pose.rotation(i, j);
  }
  const Eigen::Quaternion<firmware::Scalar> q = cdcr::model::canonical_quaternion(estimate.pose.rotation);
  pose->quaternion[0] = q.w();
  pose->quaternion[1] = q.x();
  pose->quaternion[2] = q.y();
  pose->quaternion[3] = q.z();
  pose->segment_count = rt.geometry().segment_count;
  for (int i = 0; i < 2 * pose->segment_count; ++i) pose->joints[i] = estimate.joints[i];
  pose->compensated = estimate.compensated ? 1 : 0;
  pose->count = rt.statistics().poses_published;
  pose->extrapolating = rt.extrapolating() ? 1 : 0;
  if (rt.has_uncertainty()) {
    pose->r95_mm = rt.latest_uncertainty().r95_mm;
    pose->r95_deg = rt.latest_uncertainty().r95_deg;
  }
  return CDCR_OK;
}

cdcr_result cdcr_get_setpoints(const cdcr_runtime* runtime, cdcr_setpoints* setpoints) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  if (setpoints == nullptr) return CDCR_ERROR_NULL_ARGUMENT;
  const firmware::Runtime& rt = c->runtime;
  if (!rt.has_setpoints()) return CDCR_ERROR_NO_DATA;
  *setpoints = cdcr_setpoints{};
  setpoints->cable_count = rt.geometry().cable_count();
  for (int i = 0; i < setpoints->cable_count; ++i) setpoints->lengths_mm[i] = rt.setpoints_mm()[i];
  setpoints->count = rt.setpoints_published();
  return CDCR_OK;
}

cdcr_result cdcr_get_status(const cdcr_runtime* runtime, cdcr_status* status) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  if (status == nullptr) return CDCR_ERROR_NULL_ARGUMENT;
  const firmware::Runtime& rt = c->runtime;
  const firmware::CycleStatistics& stats = rt.statistics();
  const firmware::IkReport& report = rt.last_ik_report();
  *status = cdcr_status{};
  status->state = static_cast<cdcr_state>(rt.state());
  status->fault = static_cast<cdcr_fault>(rt.active_fault());
  status->fault_detail = rt.active_fault_detail().wire_value();
  status->boot_fault = static_cast<cdcr_fault>(rt.boot_fault());
  status->ik_outcome = stats.targets_received == 0 ? CDCR_IK_NONE : static_cast<cdcr_ik_outcome>(report.outcome);
  status->ik_sequence = report.sequence;
  status->ik_running = rt.ik_running() ? 1 : 0;
  status->ik_iterations = report.iterations;
  status->ik_cycles = report.cycles;
  status->ik_position_error_mm = report.position_error_mm;
  status->ik_orientation_error_rad = report.orientation_error_rad;
  status->cycles = stats.cycles;
  status->overruns = stats.overruns;
  status->rejected_frames = stats.rejected_frames + stats.rejected_cable_sets;
  status->stale_events = stats.stale_events;
  status->targets_received = stats.targets_received;
  status->execution_max_ns = stats.execution_max_ns;
  status->execution_mean_ns = stats.execution_mean_ns();
  status->jitter_max_ns = stats.jitter_max_ns;
  status->hysteresis_unknown = rt.hysteresis().known() ? 0 : 1;
  return CDCR_OK;
}

const char* cdcr_result_name(cdcr_result result) {
  switch (result) {
    case CDCR_OK: return "ok";
    case CDCR_ERROR_NULL_ARGUMENT: return "null argument";
    case CDCR_ERROR_NOT_INITIALIZED: return "not initialized";
    case CDCR_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case CDCR_ERROR_OUT_OF_RANGE: return "out of range";
    case CDCR_ERROR_QUEUE_FULL: return "queue full";
    case CDCR_ERROR_NO_DATA: return "no data";
    case CDCR_ERROR_NOT_APPLICABLE: return "not applicable";
  }
  return "unknown result";
}

const char* cdcr_state_name(cdcr_state state) { return firmware::to_string(static_cast<firmware::RuntimeState>(state)); }

const char* cdcr_fault_name(cdcr_fault fault) { return firmware::to_string(static_cast<firmware::FaultCode>(fault)); }

}  // extern "C"
