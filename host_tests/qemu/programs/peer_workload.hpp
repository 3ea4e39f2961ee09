#pragma once
// What a peer on the bus drives the runtime with, on any board: the same
// random numbers on every run and every board, ideal drives that report the
// last setpoint of each segment every cycle, targets delivered as a planner
// sends them, and targets made with the runtime's own model. Shared by the
// MPS2 boards' measuring programs (workload.hpp) and the R5F board's
// workload (host_tests/zynqmp/programs/workload_main.cpp).

#include <algorithm>
#include <cstdint>
#include <cstring>

#include <cdcr/baremetal/ram_flash.hpp>
#include <cdcr/firmware/protocol.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/model/crc32.hpp>

namespace cdcr::qemu_programs {

namespace model = cdcr::model;
namespace firmware = cdcr::firmware;
namespace protocol = cdcr::firmware::protocol;

// xorshift32.
class Random {
 public:
  explicit Random(std::uint32_t seed) : state_(seed) {}
  float uniform(float lo, float hi) {
    state_ ^= state_ << 13;
    state_ ^= state_ >> 17;
    state_ ^= state_ << 5;
    return lo + (hi - lo) * float(state_ >> 8) * (1.0f / 16777216.0f);
  }

 private:
  std::uint32_t state_;
};

// The drives of an ideal robot, on the bus: a PeerBus is the peer's end of
// it, with deliver(frame) (a frame to the runtime) and
// take_transmitted(frame) (the next frame from the runtime; false when there
// is none): the MPS2 boards' mailbox, or the R5F board's second CAN
// controller.
struct IdealDrives {
  float lengths_mm[firmware::kMaxSegments][4] = {};
  int segments = 0;
  int silent_segment = -1;  // a drive that stops reporting

  // Takes the runtime's frames: setpoints move the drives, anything else
  // goes to `other` (a frame the workload itself answers). Then reports
  // every segment's lengths.
  template <typename PeerBus, typename OtherFrame>
  void exchange(PeerBus& bus, OtherFrame&& other) {
    hal::CanFrame frame;
    while (bus.take_transmitted(frame)) {
      protocol::CableSetpoint setpoint;
      if (protocol::decode(frame, setpoint) != protocol::DecodeStatus::ok) {
        other(frame);
        continue;
      }
      for (int k = 0; k < 4; ++k) lengths_mm[setpoint.segment][k] = float(setpoint.lengths_mm[k]);
    }
    for (int s = 0; s < segments; ++s) {
      if (s == silent_segment) continue;
      protocol::CableFeedback feedback{s, {lengths_mm[s][0], lengths_mm[s][1], lengths_mm[s][2], lengths_mm[s][3]}};
      if (protocol::encode(feedback, frame)) bus.deliver(frame);
    }
  }
  template <typename PeerBus>
  void exchange(PeerBus& bus) {
    exchange(bus, [](const hal::CanFrame&) {});
  }
};

// A target's frames as a planner sends them: the orientation of a pose
// target, the position, then the commit frame.
template <typename PeerBus>
void deliver_target(PeerBus& bus, const model::Pose<float>& target, protocol::TargetMode mode, bool tracking,
                    std::uint8_t sequence, bool refuse_extrapolating = false) {
  hal::CanFrame frame;
  if (mode == protocol::TargetMode::pose) {
    Eigen::Quaternion<float> q(target.rotation);
    q.normalize();
    protocol::encode(protocol::TargetOrientation{q.w(), q.x(), q.y(), q.z()}, frame);
    bus.deliver(frame);
  }
  protocol::encode(protocol::TargetPositionXy{target.position_mm.x(), target.position_mm.y()}, frame);
  bus.deliver(frame);
  protocol::TargetPositionZ commit{target.position_mm.z(), mode, tracking, sequence};
  commit.refuse_extrapolating = refuse_extrapolating;
  protocol::encode(commit, frame);
  bus.deliver(frame);
}

// Where the compensated model puts the tip for the given joints (targets
// are made this way, on the board, and not counted).
inline model::Pose<float> compensated_tip(const firmware::Correction& correction, const firmware::Geometry& geometry,
                                          const model::JointVector<float>& joints) {
  const model::JointVector<float> bend = model::bend_from_joints(joints);
  return model::exp(correction.predict(bend)) * model::forward_kinematics_bend(bend, geometry);
}

// ... at random joints, each segment bent at most theta_max_rad.
inline model::Pose<float> reachable_target(Random& random, const firmware::Correction& correction,
                                           const firmware::Geometry& geometry, float theta_max_rad) {
  model::JointVector<float> joints(2 * geometry.segment_count);
  for (int s = 0; s < geometry.segment_count; ++s) {
    joints[2 * s] = random.uniform(-3.14159f, 3.14159f);
    joints[2 * s + 1] = random.uniform(0.0f, std::min(theta_max_rad, geometry.segments[s].theta_max_rad));
  }
  return compensated_tip(correction, geometry, joints);
}

// The board's model image parsed and bound to `correction` (what the runtime
// itself bound at init), for the workload to make its targets with.
template <typename Board>
bool bind_board_image(Board& board, firmware::Correction& correction, model::ImageView& image) {
  const hal::MemoryRegion region = board.model_storage.model_region();
  return model::parse_image(region.data, region.size_bytes, image, model::ImageCapacity{}) == model::ImageStatus::ok &&
         correction.bind(image) == model::Status::ok;
}

// The flash the programs that update the model give the runtime: two slots,
// each a metadata sector and 16 image sectors of 4 KiB, room for a 64 KiB
// image (the golden one is about 57 KiB), in 136 KiB of the board's RAM.
// A board with a flash controller has its flash instead.
using UpdateFlash = baremetal::RamFlash<4096, 2 * (1 + 16)>;

// The board's Hal with `flash` for model updates.
template <typename Board>
hal::Hal hal_with_flash(Board& board, hal::Flash& flash) {
  hal::Hal hal = board.hal();
  hal.flash = &flash;
  return hal;
}

// `image` with another creation time, and its CRC trailer made again, into
// `other` (room for `size` bytes): the same model under another digest, for
// a model update that must be told apart from the image it replaces.
inline void copy_with_other_creation_time(const std::uint8_t* image, std::uint32_t size, std::uint8_t* other) {
  std::memcpy(other, image, size);
  std::uint32_t metadata = 0;
  std::memcpy(&metadata, other + model::image_field::metadata_offset.offset, 4);
  other[metadata + model::image_metadata_field::created_unix_s] ^= 0x01;
  const std::uint32_t crc = model::crc32(other, size - model::kImageTrailerSize);
  std::memcpy(other + size - model::kImageTrailerSize, &crc, 4);
}

// The instructions of one Runtime::run_cycle, called through a function the
// compiler cannot inline into the counted region.
__attribute__((noinline)) inline void run_cycle_opaque(firmware::Runtime& runtime, const hal::TimerTick& tick) {
  runtime.run_cycle(tick);
}

}  // namespace cdcr::qemu_programs
