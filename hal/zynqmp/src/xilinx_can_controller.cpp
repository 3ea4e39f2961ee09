#include "cdcr/zynqmp/xilinx_can_controller.hpp"

namespace cdcr::zynqmp {
namespace {

// Register offsets (UG1085, CAN registers; the same in QEMU's
// xlnx.zynqmp-can).
constexpr std::uint32_t kSoftwareReset = 0x00;  // SRR
constexpr std::uint32_t kModeSelect = 0x04;     // MSR
constexpr std::uint32_t kBaudPrescaler = 0x08;  // BRPR
constexpr std::uint32_t kBitTiming = 0x0C;      // BTR
constexpr std::uint32_t kErrorCounter = 0x10;   // ECR
constexpr std::uint32_t kErrorStatus = 0x14;    // ESR
constexpr std::uint32_t kStatus = 0x18;         // SR
constexpr std::uint32_t kInterruptStatus = 0x1C;  // ISR
constexpr std::uint32_t kInterruptClear = 0x24;   // ICR
constexpr std::uint32_t kTxFifoId = 0x30;  // then DLC, DATA1, DATA2
constexpr std::uint32_t kTxHighPriorityId = 0x40;
constexpr std::uint32_t kRxFifoId = 0x50;
constexpr std::uint32_t kRxFifoDlc = 0x54;
constexpr std::uint32_t kRxFifoData1 = 0x58;
constexpr std::uint32_t kRxFifoData2 = 0x5C;
constexpr std::uint32_t kAcceptanceFilterEnable = 0x60;  // AFR
constexpr std::uint32_t kAcceptanceMask1 = 0x64;          // AFMR1, AFIR1 at +4, next pair at +8
constexpr std::uint32_t kFilterPairStride = 8;
// Offsets of a frame's words from its ID register.
constexpr std::uint32_t kDlcWord = 0x4;
constexpr std::uint32_t kData1Word = 0x8;
constexpr std::uint32_t kData2Word = 0xC;

constexpr std::uint32_t kResetSoftwareReset = 1u << 0;  // SRR.SRST
constexpr std::uint32_t kResetEnable = 1u << 1;         // SRR.CEN
constexpr std::uint32_t kModeLoopback = 1u << 1;        // MSR.LBACK

constexpr std::uint32_t kStatusConfig = 1u << 0;
constexpr std::uint32_t kStatusLoopback = 1u << 1;
constexpr std::uint32_t kStatusNormal = 1u << 3;
constexpr std::uint32_t kStatusErrorStateShift = 7;  // SR.ESTAT, 2 bits
constexpr std::uint32_t kStatusTxHighPriorityFull = 1u << 9;
constexpr std::uint32_t kStatusTxFifoFull = 1u << 10;
constexpr std::uint32_t kStatusFilterBusy = 1u << 11;

constexpr std::uint32_t kInterruptRxOverflow = 1u << 6;
constexpr std::uint32_t kInterruptRxNotEmpty = 1u << 7;

// ESR: ACKER, BERR, STER, FMER, CRCER; write 1 to clear.
constexpr std::uint32_t kErrorStatusAll = 0x1Fu;

// The identifier word (TX/RX FIFO ID, AFMR, AFIR): the 11-bit identifier in
// IDH, then SRR (the remote-request bit of a standard frame) and IDE.
constexpr std::uint32_t kIdShift = 21;
constexpr std::uint32_t kIdRemoteRequest = 1u << 20;
constexpr std::uint32_t kIdExtended = 1u << 19;
constexpr std::uint32_t kDlcShift = 28;

// Bounded polls for state changes the controller makes within a few of its
// clocks; a controller that does not make them in this many reads is broken.
constexpr int kPollLimit = 10000;

template <typename Condition>
bool poll_until(Condition condition) {
  for (int poll = 0; poll < kPollLimit; ++poll) {
    if (condition()) return true;
  }
  return false;
}

// Data bytes 0..3 in DATA1 and 4..7 in DATA2, the first byte in the most
// significant bits.
std::uint32_t pack_data_word(const std::uint8_t* bytes) {
  return static_cast<std::uint32_t>(bytes[0]) << 24 | static_cast<std::uint32_t>(bytes[1]) << 16 |
         static_cast<std::uint32_t>(bytes[2]) << 8 | static_cast<std::uint32_t>(bytes[3]);
}

void unpack_data_word(std::uint32_t word, std::uint8_t* bytes) {
  bytes[0] = static_cast<std::uint8_t>(word >> 24);
  bytes[1] = static_cast<std::uint8_t>(word >> 16);
  bytes[2] = static_cast<std::uint8_t>(word >> 8);
  bytes[3] = static_cast<std::uint8_t>(word);
}

int count_bits(std::uint32_t bits) {
  int count = 0;
  for (; bits != 0; bits &= bits - 1) ++count;
  return count;
}

}  // namespace

bool XilinxCanController::start(const CanBitTiming& timing, CanMode mode) {
  // Reset: the controller comes back in configuration mode, FIFOs empty,
  // filters off.
  reg(kSoftwareReset) = kResetSoftwareReset;
  if (!poll_until([this] { return (reg(kStatus) & kStatusConfig) != 0; })) return false;
  if (!is_valid(timing)) return false;

  // BRPR, BTR hold each value less one.
  reg(kBaudPrescaler) = timing.prescaler - 1;
  reg(kBitTiming) = (timing.sjw - 1) << 7 | (timing.tseg2 - 1) << 4 | (timing.tseg1 - 1);
  reg(kModeSelect) = mode == CanMode::loopback ? kModeLoopback : 0u;
  reg(kSoftwareReset) = kResetEnable;

  const std::uint32_t expected = mode == CanMode::loopback ? kStatusLoopback : kStatusNormal;
  return poll_until([this, expected] { return (reg(kStatus) & expected) != 0; });
}

CanBitTiming XilinxCanController::bit_timing() const {
  const std::uint32_t prescaler = reg(kBaudPrescaler) & 0xFFu;
  const std::uint32_t timing = reg(kBitTiming);
  return CanBitTiming{prescaler + 1, (timing & 0xFu) + 1, ((timing >> 4) & 0x7u) + 1, ((timing >> 7) & 0x3u) + 1};
}

hal::CanStatus XilinxCanController::write_frame(std::uint32_t id_offset, std::uint32_t full_flag,
                                                const hal::CanFrame& frame) {
  if (!hal::is_valid(frame)) return hal::CanStatus::invalid_frame;
  if (error_state() == CanErrorState::bus_off) return hal::CanStatus::bus_off;
  if ((reg(kStatus) & full_flag) != 0) return hal::CanStatus::queue_full;
  // All four words, in this order: the write of DATA2 queues the frame
  // (QEMU 7.2 takes the words in write order, and DATA2's address as the
  // trigger).
  reg(id_offset) = frame.id << kIdShift;
  reg(id_offset + kDlcWord) = static_cast<std::uint32_t>(frame.dlc) << kDlcShift;
  reg(id_offset + kData1Word) = pack_data_word(frame.data);
  reg(id_offset + kData2Word) = pack_data_word(frame.data + 4);
  return hal::CanStatus::ok;
}

hal::CanStatus XilinxCanController::transmit(const hal::CanFrame& frame) {
  return write_frame(kTxFifoId, kStatusTxFifoFull, frame);
}

hal::CanStatus XilinxCanController::transmit_high_priority(const hal::CanFrame& frame) {
  return write_frame(kTxHighPriorityId, kStatusTxHighPriorityFull, frame);
}

bool XilinxCanController::receive(hal::CanFrame& frame) {
  for (;;) {
    if ((reg(kInterruptStatus) & kInterruptRxNotEmpty) == 0) return false;
    // Reading the ID word takes the frame off the FIFO; the other three
    // words then hold the same frame. Read in this order: QEMU 7.2's model
    // hands out the frame's words in read order, whichever of the four
    // registers is read.
    const std::uint32_t id_word = reg(kRxFifoId);
    const std::uint32_t dlc_word = reg(kRxFifoDlc);
    const std::uint32_t data1 = reg(kRxFifoData1);
    const std::uint32_t data2 = reg(kRxFifoData2);
    // The flag stays set while frames remain: the controller sets it again
    // after the clear.
    reg(kInterruptClear) = kInterruptRxNotEmpty;

    if ((id_word & (kIdExtended | kIdRemoteRequest)) != 0) {
      skipped_frames_ += 1;
      continue;
    }
    frame.id = id_word >> kIdShift;
    const std::uint32_t dlc = dlc_word >> kDlcShift;
    frame.dlc = static_cast<std::uint8_t>(dlc > hal::kMaxDataBytes ? hal::kMaxDataBytes : dlc);
    unpack_data_word(data1, frame.data);
    unpack_data_word(data2, frame.data + 4);
    return true;
  }
}

bool XilinxCanController::take_rx_overflow() {
  if ((reg(kInterruptStatus) & kInterruptRxOverflow) == 0) return false;
  reg(kInterruptClear) = kInterruptRxOverflow;
  return true;
}

bool XilinxCanController::set_filters(const hal::CanFilter* filters, std::size_t count) {
  // What the hardware cannot take is refused before anything changes.
  if (count > kXilinxCanFilters) return false;
  for (std::size_t i = 0; i < count; ++i) {
    if (filters[i].id > hal::kMaxStandardId || filters[i].mask > hal::kMaxStandardId) return false;
  }
  // Filters may only change while disabled, and once the filter unit is no
  // longer busy.
  reg(kAcceptanceFilterEnable) = 0;
  if (!poll_until([this] { return (reg(kStatus) & kStatusFilterBusy) == 0; })) return false;
  std::uint32_t enable = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t mask_offset = kAcceptanceMask1 + static_cast<std::uint32_t>(i) * kFilterPairStride;
    // IDE and SRR are compared too (and must be 0): standard data frames only.
    reg(mask_offset) = filters[i].mask << kIdShift | kIdRemoteRequest | kIdExtended;
    reg(mask_offset + 4) = filters[i].id << kIdShift;
    enable |= 1u << i;
  }
  reg(kAcceptanceFilterEnable) = enable;
  return true;
}

CanControllerErrors XilinxCanController::errors() const {
  const std::uint32_t counters = reg(kErrorCounter);
  return CanControllerErrors{static_cast<std::uint8_t>(counters & 0xFFu),
                             static_cast<std::uint8_t>((counters >> 8) & 0xFFu), error_state()};
}

CanErrorState XilinxCanController::error_state() const {
  const std::uint32_t status = reg(kStatus);
  if ((status & kStatusConfig) != 0) return CanErrorState::configuration;
  const auto state = static_cast<CanErrorState>((status >> kStatusErrorStateShift) & 0x3u);
  // ESTAT reads 0 only in configuration mode on the hardware; QEMU 7.2's
  // model leaves it 0 on the bus too, where the controller is error-active.
  return state == CanErrorState::configuration ? CanErrorState::error_active : state;
}

std::uint32_t XilinxCanController::take_error_flags() {
  const std::uint32_t flags = reg(kErrorStatus) & kErrorStatusAll;
  if (flags != 0) reg(kErrorStatus) = flags;
  return static_cast<std::uint32_t>(count_bits(flags));
}

}  // namespace cdcr::zynqmp
