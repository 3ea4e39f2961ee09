// Power loss at every flash operation of a model update, the way MCUboot's
// simulator tests its swap: a whole transfer and commit is run once to count
// its flash operations, then again for every k with the power cut at the
// k-th (torn: half done; complete: done but never reported). After each cut
// the board reboots from what the flash holds and must run a complete, valid
// image (the old one before the commit point, the new one after it, never a
// mix, never DEGRADED), and the update must resume and finish.

#include <cstdio>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "model_update_fixture.hpp"

namespace cdcr::test_support {
namespace {

constexpr std::uint32_t kSectorBytes = 512;
constexpr std::uint32_t kSectors = 2 * 40;
constexpr sim::SimFlash::Timing kTiming{2, 0};

struct Figures {
  int reset_points = 0;
  int came_up_old = 0;
  int came_up_new = 0;
  int resumed_after_blocks = 0;  // reboots whose slot already held blocks the update went on from
  int finished = 0;
};

// Contiguous blocks the target slot's progress says are in flash.
std::uint32_t blocks_in_flash(const sim::SimFlash& flash, int slot) {
  const firmware::SlotGeometry g = firmware::slot_geometry(flash, slot);
  firmware::TransferRecord record;
  if (!firmware::decode_record(flash.read() + g.offset, record)) return 0;
  std::uint32_t blocks = 0;
  while (blocks < g.progress_capacity() && flash.read()[g.progress_offset() + blocks] == 0) ++blocks;
  return blocks;
}

TEST(PowerFail, EveryFlashOperationOfAnUpdate) {
  const std::vector<std::uint8_t> old_image = update_test_image(380, 1);
  const std::vector<std::uint8_t> new_image = update_test_image(400, 2);
  sim::SimFlash provisioned(kSectorBytes, kSectors, 256, kTiming);
  provision_slot(provisioned, 0, old_image, 1);
  const std::vector<std::uint8_t> snapshot(provisioned.raw(), provisioned.raw() + provisioned.size_bytes());

  // The clean run: how many operations, and that the header is the last.
  std::uint64_t total_operations = 0;
  {
    sim::SimFlash flash(kSectorBytes, kSectors, 256, kTiming);
    std::memcpy(flash.raw(), snapshot.data(), snapshot.size());
    UpdateBoard board(flash, {});
    SentImage sender_image(new_image);
    UpdateSender& sender = sender_image.sender;
    board.run_sender(sender, 20000);
    ASSERT_EQ(sender.outcome(), UpdateSender::Outcome::committed);
    total_operations = flash.operations();
    std::printf("[ figures  ] %zu-byte image, %u blocks: %llu flash operations (%llu erases, %llu programs)\n",
                new_image.size(), sender.total_blocks(), static_cast<unsigned long long>(total_operations),
                static_cast<unsigned long long>(flash.erases()), static_cast<unsigned long long>(flash.programs()));
  }
  ASSERT_GE(total_operations, 500u);

  for (const sim::SimFlash::Cut cut : {sim::SimFlash::Cut::torn, sim::SimFlash::Cut::complete}) {
    const char* cut_name = cut == sim::SimFlash::Cut::torn ? "torn" : "complete";
    Figures figures;
    for (std::uint64_t k = 1; k <= total_operations; ++k) {
      SCOPED_TRACE(testing::Message() << cut_name << " cut at operation " << k);
      sim::SimFlash flash(kSectorBytes, kSectors, 256, kTiming);
      std::memcpy(flash.raw(), snapshot.data(), snapshot.size());
      UpdateBoard board(flash, {});
      flash.power_loss_at(k, cut);
      auto sender = std::make_unique<SentImage>(new_image);
      board.run_sender(sender->sender, 20000);
      ASSERT_TRUE(flash.power_lost());

      // Reboot on what the flash holds.
      board.boot();
      figures.reset_points += 1;
      ASSERT_EQ(board.runtime->state(), firmware::RuntimeState::run) << "DEGRADED after a torn write";
      const std::vector<std::uint8_t> running = board.active_image();
      // The commit point is the header, the update's last operation.
      const bool committed = k > total_operations || (k == total_operations && cut == sim::SimFlash::Cut::complete);
      if (running == new_image) {
        figures.came_up_new += 1;
        ASSERT_TRUE(committed) << "the new image before its commit point";
      } else {
        ASSERT_EQ(running, old_image) << "neither the old nor the new image";
        figures.came_up_old += 1;
        ASSERT_FALSE(committed) << "the old image after the commit point";
      }
      if (blocks_in_flash(flash, 1) > 0 && !committed) figures.resumed_after_blocks += 1;

      // The update resumes: the host restarts too every other time.
      if (!committed) {
        if (k % 2 == 0) {
          sender = std::make_unique<SentImage>(new_image);
          board.run_sender(sender->sender, 20000);
        } else {
          board.run_sender(sender->sender, 20000, false);
        }
        ASSERT_EQ(sender->sender.outcome(), UpdateSender::Outcome::committed);
      }
      ASSERT_EQ(board.active_image(), new_image);
      board.boot();
      ASSERT_EQ(board.active_image(), new_image);
      ASSERT_EQ(board.runtime->model_update().active_slot(), 1);
      figures.finished += 1;
    }
    std::printf("[ figures  ] %s cuts: %d reset points, %d came up on the old image, %d on the new, 0 mixed, "
                "0 DEGRADED; %d resumed with blocks already in flash; %d finished\n",
                cut_name, figures.reset_points, figures.came_up_old, figures.came_up_new,
                figures.resumed_after_blocks, figures.finished);
    EXPECT_EQ(figures.finished, figures.reset_points);
    EXPECT_EQ(figures.came_up_old + figures.came_up_new, figures.reset_points);
  }
}

}  // namespace
}  // namespace cdcr::test_support
