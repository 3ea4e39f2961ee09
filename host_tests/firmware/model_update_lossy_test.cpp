// Model transfers over a link that loses, repeats and reorders frames, in
// both directions: the runtime and the sender in lockstep on the simulated
// bus, with a faulty link between the sender and the bus. A lost frame is
// never a refused image: the transfer resends and commits.

#include <cstdio>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "model_update_fixture.hpp"

namespace cdcr::test_support {
namespace {

using firmware::protocol::UpdateReason;
using firmware::protocol::UpdateState;

struct Faults {
  const char* name;
  double drop;       // a frame lost
  double duplicate;  // a frame sent twice
  double reorder;    // a frame held back behind the next one
  int training_points;  // of the image sent: its size
  int resend_after_cycles;  // the sender's silence before it STARTs again
};

void PrintTo(const Faults& faults, std::ostream* os) { *os << faults.name; }

// One direction of the link, random with a fixed seed.
class FaultyLink {
 public:
  FaultyLink(const Faults& faults, std::uint32_t seed) : faults_(faults), random_(seed) {}

  std::vector<hal::CanFrame> pass(const std::vector<hal::CanFrame>& frames) {
    std::vector<hal::CanFrame> passed;
    for (const hal::CanFrame& frame : frames) {
      if (chance(faults_.drop)) continue;
      const int copies = chance(faults_.duplicate) ? 2 : 1;
      for (int copy = 0; copy < copies; ++copy) {
        if (holding_) {
          passed.push_back(frame);
          passed.push_back(held_);
          holding_ = false;
        } else if (chance(faults_.reorder)) {
          held_ = frame;
          holding_ = true;
        } else {
          passed.push_back(frame);
        }
      }
    }
    return passed;
  }

 private:
  bool chance(double p) { return p > 0 && std::uniform_real_distribution<double>(0, 1)(random_) < p; }

  Faults faults_;
  std::mt19937 random_;
  hal::CanFrame held_;
  bool holding_ = false;  // a held frame goes out behind the next one, in this cycle or a later one
};

struct Transfer {
  UpdateSender::Outcome outcome = UpdateSender::Outcome::running;
  UpdateReason refusal = UpdateReason::none;
  int cycles = 0;
  std::uint32_t frames = 0;
  std::uint32_t restarts = 0;
  std::uint32_t rewinds = 0;
  bool new_image_runs = false;
};

Transfer transfer_over(const Faults& faults, std::uint32_t seed, const std::vector<std::uint8_t>& old_image,
                       const std::vector<std::uint8_t>& new_image) {
  sim::SimFlash flash{1024, 64, 256};
  provision_slot(flash, 0, old_image, 1);
  UpdateBoard board(flash, {});
  board.cycle();
  SentImage sent(new_image);
  UpdateSender& sender = sent.sender;
  sender.resend_after = faults.resend_after_cycles;  // the board's clock: 1 ms a cycle
  FaultyLink to_runtime(faults, seed);
  FaultyLink to_host(faults, seed ^ 0x5A5A5A5Au);
  FrameQueue out;
  sender.start(out, board.now_ms());
  Transfer result;
  while (result.cycles < 200'000 && sender.outcome() == UpdateSender::Outcome::running) {
    sender.pump(board.now_ms(), out, 44);
    board.cycle(to_runtime.pass(out.take()));
    for (const hal::CanFrame& report : to_host.pass(board.take_reports())) {
      sender.on_report(report, board.now_ms(), out);
    }
    ++result.cycles;
  }
  for (int i = 0; i < 3; ++i) board.cycle();
  result.outcome = sender.outcome();
  result.refusal = sender.refusal();
  result.frames = sender.frames_sent();
  result.restarts = sender.restarts();
  result.rewinds = sender.rewinds();
  result.new_image_runs = board.active_image() == new_image && board.runtime->state() == firmware::RuntimeState::run;
  return result;
}

class LossyTransferTest : public ::testing::TestWithParam<Faults> {};

TEST_P(LossyTransferTest, CommitsTheImage) {
  const Faults faults = GetParam();
  const std::vector<std::uint8_t> old_image = update_test_image(40, 1);
  const std::vector<std::uint8_t> new_image = update_test_image(faults.training_points, 2);
  int cycles = 0;
  std::uint32_t frames = 0, restarts = 0, rewinds = 0;
  constexpr int kSeeds = 40;
  for (std::uint32_t seed = 1; seed <= kSeeds; ++seed) {
    SCOPED_TRACE(testing::Message() << faults.name << ", seed " << seed);
    const Transfer t = transfer_over(faults, seed, old_image, new_image);
    EXPECT_EQ(t.outcome, UpdateSender::Outcome::committed) << "refused: reason " << int(t.refusal);
    EXPECT_TRUE(t.new_image_runs);
    cycles += t.cycles;
    frames += t.frames;
    restarts += t.restarts;
    rewinds += t.rewinds;
  }
  std::printf("[ figures  ] %s: %zu-byte image committed in %d cycles, %u frames, %u restarts, %u rewinds "
              "(mean of %d seeds)\n",
              faults.name, new_image.size(), cycles / kSeeds, frames / kSeeds, restarts / kSeeds, rewinds / kSeeds,
              kSeeds);
}

constexpr Faults kFaults[] = {
    // At 1 %, the runtime of the busy machine where `cdcr deploy` was
    // refused: 36 ms a cycle against the sender's 200 ms, so that the
    // sender STARTs again after 6 silent cycles, and a larger image.
    {"NoLoss", 0, 0, 0, 60, 200},    {"Lost1", 0.01, 0, 0, 600, 6},      {"Lost10", 0.10, 0, 0, 60, 200},
    {"Lost30", 0.30, 0, 0, 60, 200}, {"Repeated10", 0, 0.10, 0, 60, 200}, {"Reordered10", 0, 0, 0.10, 60, 200},
    {"EachTen", 0.10, 0.10, 0.10, 60, 200},
};

std::string faults_name(const ::testing::TestParamInfo<Faults>& info) { return info.param.name; }

INSTANTIATE_TEST_SUITE_P(Link, LossyTransferTest, ::testing::ValuesIn(kFaults), faults_name);

// Single frames lost or repeated. The cause of "refused: malformed" on a
// busy bus: a START whose digest frames did not all arrive (one lost, or
// START repeated, or ahead of its last digest frame).
class LostFrameTest : public ::testing::Test {
 protected:
  void SetUp() override {
    provision_slot(flash, 0, update_test_image(40, 1), 1);
    board = std::make_unique<UpdateBoard>(flash, std::vector<std::uint8_t>{});
    board->cycle();
  }
  std::vector<UpdateReason> reasons() { return test_support::report_reasons(board->take_reports()); }
  UpdateState update_state() const { return board->runtime->model_update().state(); }
  // Cycles (100 at most) until the board receives the transfer's blocks.
  void cycle_until_receiving() {
    for (int i = 0; i < 100 && update_state() != UpdateState::receiving; ++i) board->cycle();
  }
  sim::SimFlash flash{1024, 64, 256};
  std::unique_ptr<UpdateBoard> board;
  SentImage sent{update_test_image(60, 2)};
};

TEST_F(LostFrameTest, ANewTransferAsksForTheDigestAgain) {
  FrameQueue out;
  sent.sender.start(out, board->now_ms());
  out.frames.erase(out.frames.begin() + 3);  // digest part 3 lost
  board->cycle(out.take());
  const std::vector<hal::CanFrame> reports = board->reports;
  EXPECT_EQ(reasons(), std::vector<UpdateReason>{UpdateReason::no_transfer});
  EXPECT_EQ(update_state(), UpdateState::idle);
  // The sender answers with the digest and START again, and the transfer
  // begins.
  for (const hal::CanFrame& report : reports) sent.sender.on_report(report, board->now_ms(), out);
  EXPECT_EQ(sent.sender.restarts(), 1u);
  board->cycle(out.take());
  EXPECT_EQ(reasons(), std::vector<UpdateReason>{UpdateReason::none});
  EXPECT_EQ(update_state(), UpdateState::preparing);
}

TEST_F(LostFrameTest, ARepeatedStartGoesOnWithTheTransfer) {
  FrameQueue out;
  sent.sender.start(out, board->now_ms());
  out.frames.push_back(out.frames.back());  // START twice
  board->cycle(out.take());
  EXPECT_EQ(reasons(), (std::vector<UpdateReason>{UpdateReason::none, UpdateReason::none}));
  cycle_until_receiving();
  EXPECT_EQ(update_state(), UpdateState::receiving);
  // START again later with a digest frame lost: the transfer goes on.
  sent.sender.start(out, board->now_ms());
  out.frames.erase(out.frames.begin());
  board->take_reports();
  board->cycle(out.take());
  EXPECT_EQ(reasons(), std::vector<UpdateReason>{UpdateReason::none});
  EXPECT_EQ(update_state(), UpdateState::receiving);
}

// A block header repeated before its data: the block is taken once, and
// no block is called missing.
TEST_F(LostFrameTest, ARepeatedBlockHeaderIsNotAMissingBlock) {
  FrameQueue out;
  sent.sender.start(out, board->now_ms());
  board->cycle(out.take());
  cycle_until_receiving();
  ASSERT_EQ(update_state(), UpdateState::receiving);
  board->take_reports();
  sent.sender.send_block(0, out);
  out.frames.insert(out.frames.begin() + 1, out.frames.front());
  board->cycle(out.take());
  for (int i = 0; i < 20; ++i) board->cycle();
  for (UpdateReason reason : reasons()) EXPECT_EQ(reason, UpdateReason::none);
  EXPECT_EQ(board->runtime->model_update().blocks_in_flash(), 1u);
}

}  // namespace
}  // namespace cdcr::test_support
