#pragma once
// An in-process CAN bus between up to kMaxNodes nodes. Queues are fixed
// rings, so the simulated bus never allocates either.
//
// Untimed (the default): every node's send() is delivered at once to every
// other node's receive queue that accepts it, in order, with no arbitration
// delay: an infinitely fast bus.
//
// Timed (set_timing): the bus takes time as a real one. send() puts the
// frame in the node's transmit queue (first in, first out, as a controller's
// FIFO); whenever the bus is idle, the frames at the head of every node's
// queue arbitrate and the lowest identifier goes on the wire; it takes its
// bits at the bus's rates (hal/can_timing.hpp, the stuffing of its actual
// content in its format, classical or FD, the interframe space included) and is delivered when its last
// bit has passed. Time is the clock's: the bus catches up to the clock's
// now on every receive() and send(), deciding arbitration only for instants
// strictly before now, since a node may still send at now itself.

#include <array>
#include <cstddef>
#include <cstdint>

#include <cdcr/hal/can_bus.hpp>
#include <cdcr/hal/can_filter_bank.hpp>
#include <cdcr/hal/can_frame_ring.hpp>
#include <cdcr/hal/can_timing.hpp>
#include <cdcr/hal/clock.hpp>

namespace cdcr::sim {

class VirtualCanBus;

class VirtualCanNode final : public hal::CanBus {
 public:
  // Depth of each node's receive queue (a board's controller FIFO plays
  // this role); beyond it frames are lost and counted as overruns.
  static constexpr std::size_t kRxQueueDepth = 128;
  // Depth of each node's transmit queue on a timed bus; beyond it send()
  // refuses with queue_full, as a controller whose FIFO is full.
  static constexpr std::size_t kTxQueueDepth = 64;

  hal::CanStatus send(const hal::CanFrame& frame) override;
  hal::CanStatus receive(hal::CanFrame& frame) override;
  bool set_filters(const hal::CanFilter* filters, std::size_t count) override {
    return filters_.assign(filters, count);
  }
  hal::CanErrorCounters error_counters() const override { return counters_; }
  bool fd_capable() const override;

  std::size_t pending() const { return queue_.size(); }
  // Frames waiting to go on a timed bus (always 0 untimed).
  std::size_t transmit_pending() const { return tx_.size(); }
  // Simulates a node dropping off the bus: its sends fail with bus_off.
  void set_bus_off(bool bus_off) { bus_off_ = bus_off; }

 private:
  friend class VirtualCanBus;
  struct Queued {
    hal::CanFrame frame;
    std::int64_t queued_ns = 0;
  };
  void deliver(const hal::CanFrame& frame);

  VirtualCanBus* bus_ = nullptr;
  hal::CanFrameRing<kRxQueueDepth> queue_;
  hal::FixedRing<Queued, kTxQueueDepth> tx_;
  hal::CanFilterBank<> filters_;
  hal::CanErrorCounters counters_{};
  bool bus_off_ = false;
};

// One frame's passage on a timed bus.
struct CanTransfer {
  hal::CanFrame frame;
  int sender = 0;              // node index
  std::int64_t queued_ns = 0;  // send()
  std::int64_t start_ns = 0;   // its SOF: it won arbitration
  std::int64_t end_ns = 0;     // its last bit (and the interframe space): delivered
  hal::CanFrameBits bits;
};

// Told of every frame a timed bus delivers, in order.
class CanTransferObserver {
 public:
  virtual void on_transfer(const CanTransfer& transfer) = 0;

 protected:
  ~CanTransferObserver() = default;
};

class VirtualCanBus {
 public:
  static constexpr int kMaxNodes = 4;

  VirtualCanBus();
  VirtualCanBus(const VirtualCanBus&) = delete;
  VirtualCanBus& operator=(const VirtualCanBus&) = delete;

  VirtualCanNode& node(int index) { return nodes_[static_cast<std::size_t>(index)]; }

  // Makes the bus timed, at `rates` (nominal > 0; data > 0 for FD frames
  // that switch their bit rate), on `clock`'s time. Before any frame is sent.
  void set_timing(const hal::MonotonicClock& clock, const hal::CanBitRates& rates);
  // A CAN FD bus: its nodes send FD frames as well as classical ones (an FD
  // frame that switches its bit rate only on a bus timed with a data rate,
  // or on an untimed one). Classical by default.
  void set_fd(bool fd) { fd_ = fd; }
  bool fd() const { return fd_; }
  bool timed() const { return clock_ != nullptr; }
  const hal::CanBitRates& rates() const { return rates_; }
  void set_observer(CanTransferObserver* observer) { observer_ = observer; }

  // Delivers what has passed by the clock's now (timed; nothing untimed).
  void catch_up();
  // Of a timed bus: the time the wire has carried frames (ns), and the
  // frames it has delivered.
  std::int64_t busy_ns() const { return busy_ns_; }
  std::uint64_t transfers() const { return transfers_; }

 private:
  friend class VirtualCanNode;
  void broadcast(const VirtualCanNode& sender, const hal::CanFrame& frame);
  hal::CanStatus enqueue(VirtualCanNode& sender, const hal::CanFrame& frame);
  // The node whose head frame wins the next arbitration, and when it
  // starts; -1 when no node has a frame.
  int next_winner(std::int64_t& start_ns) const;

  std::array<VirtualCanNode, kMaxNodes> nodes_;
  const hal::MonotonicClock* clock_ = nullptr;
  hal::CanBitRates rates_{};
  CanTransferObserver* observer_ = nullptr;
  bool fd_ = false;
  bool in_flight_ = false;
  CanTransfer flight_{};
  std::int64_t idle_from_ns_ = 0;  // when the last frame's interframe space ended
  std::int64_t busy_ns_ = 0;
  std::uint64_t transfers_ = 0;
};

}  // namespace cdcr::sim
