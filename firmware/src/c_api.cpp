// The C API (cdcr/cdcr.h): the runtime behind a HAL made of the caller's
// callbacks, placed in the caller's storage. Cable lengths and targets are
// encoded into the protocol's frames and queued on the in-memory bus the
// runtime reads, so they pass the same checks as frames from a real bus;
// the runtime's own frames go to can_send, or nowhere.

#include "cdcr/cdcr.h"

#include <cmath>
#include <cstdint>
#include <new>

#include "cdcr/firmware/runtime.hpp"

namespace cdcr::firmware {
namespace {

// Frames queued between two steps: one cable frame per segment twice over,
// two targets (three frames each) and a payload.
constexpr int kInputQueueDepth = 2 * kMaxSegments + 6 + 1;
constexpr std::uint32_t kInitializedMagic = 0x43444352u;  // "CDCR"

class CallbackClock final : public hal::MonotonicClock {
 public:
  explicit CallbackClock(const cdcr_callbacks& callbacks) : callbacks_(callbacks) {}
  std::int64_t now_ns() const override {
    return callbacks_.now_ns != nullptr ? callbacks_.now_ns(callbacks_.user) : 0;
  }

 private:
  const cdcr_callbacks& callbacks_;
};

// The caller calls cdcr_step() once per period; this only keeps the schedule
// so that lateness shows as jitter and missed releases.
class SteppedTimer final : public hal::PeriodicTimer {
 public:
  explicit SteppedTimer(const hal::MonotonicClock& clock) : clock_(clock) {}
  void start(std::int64_t period_ns) override {
    period_ns_ = period_ns > 0 ? period_ns : 0;
    started_ = false;
    overruns_ = 0;
  }
  hal::TimerTick wait_next() override {
    hal::TimerTick tick;
    const std::int64_t now = clock_.now_ns();
    if (period_ns_ == 0) {
      tick.release_ns = now;
      return tick;
    }
    if (!started_) {
      started_ = true;
      next_release_ns_ = now;
    }
    if (now >= next_release_ns_ + period_ns_) {
      const std::int64_t missed = (now - next_release_ns_) / period_ns_;
      tick.missed_releases = static_cast<std::uint32_t>(missed);
      overruns_ += tick.missed_releases;
      next_release_ns_ += missed * period_ns_;
    }
    tick.release_ns = next_release_ns_;
    next_release_ns_ += period_ns_;
    return tick;
  }
  std::int64_t period_ns() const override { return period_ns_; }
  std::uint32_t overruns() const override { return overruns_; }

 private:
  const hal::MonotonicClock& clock_;
  std::int64_t period_ns_ = 0;
  std::int64_t next_release_ns_ = 0;
  bool started_ = false;
  std::uint32_t overruns_ = 0;
};

// Frames queued by the cdcr_set_* functions come first, then the caller's bus.
class CallbackBus final : public hal::CanBus {
 public:
  explicit CallbackBus(const cdcr_callbacks& callbacks) : callbacks_(callbacks) {}

  bool has_room(int frames) const { return count_ + frames <= kInputQueueDepth; }
  void queue(const hal::CanFrame& frame) {
    queue_[(head_ + count_) % kInputQueueDepth] = frame;
    ++count_;
  }

  hal::CanStatus send(const hal::CanFrame& frame) override {
    if (callbacks_.can_send == nullptr) return hal::CanStatus::ok;
    cdcr_can_frame out{};
    out.id = frame.id;
    out.dlc = frame.dlc;
    for (int i = 0; i < 8; ++i) out.data[i] = frame.data[i];
    if (callbacks_.can_send(callbacks_.user, &out) == 0) return hal::CanStatus::ok;
    ++counters_.tx_dropped;
    return hal::CanStatus::queue_full;
  }

  hal::CanStatus receive(hal::CanFrame& frame) override {
    if (count_ > 0) {
      frame = queue_[head_];
      head_ = (head_ + 1) % kInputQueueDepth;
      --count_;
      return hal::CanStatus::ok;
    }
    cdcr_can_frame in{};
    if (callbacks_.can_receive == nullptr || callbacks_.can_receive(callbacks_.user, &in) != 1) {
      return hal::CanStatus::empty;
    }
    frame.id = in.id;
    frame.dlc = in.dlc <= 8 ? in.dlc : 8;
    for (int i = 0; i < 8; ++i) frame.data[i] = in.data[i];
    return hal::CanStatus::ok;
  }

  // Without a bus of the caller's there is nothing foreign to filter.
  bool set_filters(const hal::CanFilter* filters, std::size_t count) override {
    if (callbacks_.can_receive == nullptr) return true;
    if (callbacks_.can_set_filters == nullptr || count > std::size_t(kMaxCanFilters)) return false;
    cdcr_can_filter out[kMaxCanFilters] = {};
    for (std::size_t i = 0; i < count; ++i) out[i] = cdcr_can_filter{filters[i].id, filters[i].mask};
    return callbacks_.can_set_filters(callbacks_.user, out, count) == 1;
  }

  hal::CanErrorCounters error_counters() const override { return counters_; }

 private:
  const cdcr_callbacks& callbacks_;
  hal::CanFrame queue_[kInputQueueDepth] = {};
  int head_ = 0;
  int count_ = 0;
  hal::CanErrorCounters counters_;
};

class ImageStorage final : public hal::ModelStorage {
 public:
  ImageStorage(const std::uint8_t* data, std::uint32_t size) : region_{data, data != nullptr ? size : 0} {}
  hal::MemoryRegion model_region() const override { return region_; }

 private:
  hal::MemoryRegion region_;
};

class CallbackConsole final : public hal::Console {
 public:
  explicit CallbackConsole(const cdcr_callbacks& callbacks) : callbacks_(callbacks) {}
  void write_line(const char* line) override {
    if (callbacks_.console_write_line != nullptr) callbacks_.console_write_line(callbacks_.user, line);
  }

 private:
  const cdcr_callbacks& callbacks_;
};

// Everything cdcr_runtime holds. The HAL objects come before the runtime,
// which keeps references to them.
struct CRuntime {
  CRuntime(const cdcr_config& config, const Geometry& fallback)
      : callbacks(config.callbacks),
        clock(callbacks),
        timer(clock),
        bus(callbacks),
        storage(config.model_image, config.model_image_size),
        console(callbacks),
        runtime(hal::Hal{clock, timer, bus, storage, console}, fallback) {}

  std::uint32_t magic = 0;
  cdcr_callbacks callbacks;
  CallbackClock clock;
  SteppedTimer timer;
  CallbackBus bus;
  ImageStorage storage;
  CallbackConsole console;
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

bool finite(float value) { return std::isfinite(value); }

bool geometry_from_config(const cdcr_geometry& in, Geometry& out) {
  if (in.segment_count == 0 && in.backbone_length_mm == 0 && in.anchor_radius_mm == 0 && in.theta_max_rad == 0) {
    out = Geometry::prototype();
    return true;
  }
  out = Geometry::uniform(in.segment_count, in.backbone_length_mm, in.anchor_radius_mm, in.theta_max_rad);
  return out.validate() == model::Status::ok;
}

}  // namespace
}  // namespace cdcr::firmware

using cdcr::firmware::CRuntime;
namespace firmware = cdcr::firmware;
namespace protocol = cdcr::firmware::protocol;

static_assert(int(CDCR_STATE_FAULT) == int(firmware::RuntimeState::fault), "states as in fault.hpp");
static_assert(int(CDCR_FAULT_PAYLOAD_INVALID) == int(firmware::FaultCode::payload_invalid),
              "fault codes as in fault.hpp");
static_assert(int(CDCR_IK_IN_PROGRESS) == int(protocol::IkOutcome::in_progress), "outcomes as in messages.hpp");
static_assert(int(CDCR_IK_REFUSED_EXTRAPOLATING) == int(protocol::IkOutcome::refused_extrapolating),
              "outcomes as in messages.hpp");
static_assert(int(CDCR_TARGET_POSE) == int(protocol::TargetMode::pose), "modes as in messages.hpp");
static_assert(CDCR_MAX_SEGMENTS == firmware::kMaxSegments, "segment capacity as in capacity.hpp");

extern "C" {

size_t cdcr_runtime_storage_size(void) { return firmware::kStorageNeeded; }

cdcr_result cdcr_init(cdcr_runtime* runtime, const cdcr_config* config) {
  if (runtime == nullptr || config == nullptr) return CDCR_ERROR_NULL_ARGUMENT;
  if (config->model_image == nullptr && config->model_image_size != 0) return CDCR_ERROR_NULL_ARGUMENT;
  if (config->period_ns < 0) return CDCR_ERROR_INVALID_ARGUMENT;
  firmware::Geometry fallback;
  if (!firmware::geometry_from_config(config->fallback_geometry, fallback)) return CDCR_ERROR_INVALID_ARGUMENT;
  auto* c = new (firmware::aligned_storage(runtime)) CRuntime(*config, fallback);
  c->timer.start(config->period_ns);
  c->runtime.init();
  c->magic = firmware::kInitializedMagic;
  return CDCR_OK;
}

cdcr_result cdcr_step(cdcr_runtime* runtime) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  c->runtime.run_cycle(c->timer.wait_next());
  return CDCR_OK;
}

cdcr_result cdcr_set_segment_cable_lengths(cdcr_runtime* runtime, int segment, const float lengths_mm[4]) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  if (lengths_mm == nullptr) return CDCR_ERROR_NULL_ARGUMENT;
  if (segment < 0 || segment >= c->runtime.geometry().segment_count) return CDCR_ERROR_INVALID_ARGUMENT;
  protocol::CableFeedback feedback;
  feedback.segment = segment;
  for (int k = 0; k < 4; ++k) {
    if (!protocol::cable_length_encodable(lengths_mm[k])) return CDCR_ERROR_OUT_OF_RANGE;
    feedback.lengths_mm[k] = lengths_mm[k];
  }
  if (!c->bus.has_room(1)) return CDCR_ERROR_QUEUE_FULL;
  cdcr::hal::CanFrame frame;
  protocol::encode(feedback, frame);
  c->bus.queue(frame);
  return CDCR_OK;
}

cdcr_result cdcr_set_cable_lengths(cdcr_runtime* runtime, const float* lengths_mm, size_t count) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  if (lengths_mm == nullptr) return CDCR_ERROR_NULL_ARGUMENT;
  const int segments = c->runtime.geometry().segment_count;
  if (count != size_t(4 * segments)) return CDCR_ERROR_INVALID_ARGUMENT;
  // All or nothing: check every value and the room first.
  for (size_t i = 0; i < count; ++i) {
    if (!protocol::cable_length_encodable(lengths_mm[i])) return CDCR_ERROR_OUT_OF_RANGE;
  }
  if (!c->bus.has_room(segments)) return CDCR_ERROR_QUEUE_FULL;
  for (int s = 0; s < segments; ++s) cdcr_set_segment_cable_lengths(runtime, s, lengths_mm + 4 * s);
  return CDCR_OK;
}

cdcr_result cdcr_set_payload(cdcr_runtime* runtime, float payload_kg) {
  CRuntime* c = nullptr;
  if (const cdcr_result r = firmware::check(runtime, c); r != CDCR_OK) return r;
  cdcr::hal::CanFrame frame;
  if (!protocol::encode(protocol::Payload{payload_kg}, frame)) return CDCR_ERROR_OUT_OF_RANGE;
  if (!c->bus.has_room(1)) return CDCR_ERROR_QUEUE_FULL;
  c->bus.queue(frame);
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
    if (!firmware::finite(p) || std::fabs(p) > kMaxPositionMm) return CDCR_ERROR_OUT_OF_RANGE;
  }
  if (pose) {
    double norm2 = 0;
    for (const float q : target->quaternion) {
      if (!firmware::finite(q)) return CDCR_ERROR_OUT_OF_RANGE;
      norm2 += double(q) * q;
    }
    if (std::fabs(std::sqrt(norm2) - 1.0) > protocol::kQuaternionNormTolerance) return CDCR_ERROR_INVALID_ARGUMENT;
  }
  if (!c->bus.has_room(pose ? 3 : 2)) return CDCR_ERROR_QUEUE_FULL;
  cdcr::hal::CanFrame frame;
  if (pose) {
    protocol::encode(protocol::TargetOrientation{target->quaternion[0], target->quaternion[1],
                                                 target->quaternion[2], target->quaternion[3]},
                     frame);
    c->bus.queue(frame);
  }
  protocol::encode(protocol::TargetPositionXy{target->position_mm[0], target->position_mm[1]}, frame);
  c->bus.queue(frame);
  protocol::TargetPositionZ commit;
  commit.z_mm = target->position_mm[2];
  commit.mode = pose ? protocol::TargetMode::pose : protocol::TargetMode::position;
  commit.tracking = target->tracking != 0;
  commit.refuse_extrapolating = target->refuse_extrapolating != 0;
  commit.sequence = target->sequence;
  protocol::encode(commit, frame);
  c->bus.queue(frame);
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
  Eigen::Quaternion<firmware::Scalar> q(estimate.pose.rotation);
  q.normalize();
  const float sign = q.w() < 0 ? -1.0f : 1.0f;
  pose->quaternion[0] = sign * q.w();
  pose->quaternion[1] = sign * q.x();
  pose->quaternion[2] = sign * q.y();
  pose->quaternion[3] = sign * q.z();
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
  setpoints->cable_count = 4 * rt.geometry().segment_count;
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
  }
  return "unknown result";
}

const char* cdcr_state_name(cdcr_state state) { return firmware::to_string(static_cast<firmware::RuntimeState>(state)); }

const char* cdcr_fault_name(cdcr_fault fault) { return firmware::to_string(static_cast<firmware::FaultCode>(fault)); }

}  // extern "C"
