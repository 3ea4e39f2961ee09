// Model updates over CAN: the SHA-256, the slot records, a transfer and its
// commit and rollback with the runtime running, and every kind of bad input
// refused with its reason while the active model keeps running.

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/firmware/model_slots.hpp>
#include <cdcr/firmware/sha256.hpp>

#include "model_update_fixture.hpp"

namespace cdcr::test_support {
namespace {

using firmware::protocol::UpdateReason;
using firmware::protocol::UpdateState;

std::string hex(const std::uint8_t (&digest)[firmware::kSha256Bytes]) {
  static const char* digits = "0123456789abcdef";
  std::string text;
  for (std::uint8_t byte : digest) {
    text += digits[byte >> 4];
    text += digits[byte & 0xF];
  }
  return text;
}

std::string sha256_hex(const std::string& message) {
  std::uint8_t digest[firmware::kSha256Bytes];
  firmware::sha256(reinterpret_cast<const std::uint8_t*>(message.data()), message.size(), digest);
  return hex(digest);
}

// FIPS 180-4 examples; the rest from Python's hashlib.
TEST(Sha256, KnownVectors) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1'000'000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  // python3 -c "import hashlib; print(hashlib.sha256(bytes(range(256)) * 3).hexdigest())"
  std::string bytes;
  for (int r = 0; r < 3; ++r) {
    for (int i = 0; i < 256; ++i) bytes += static_cast<char>(i);
  }
  EXPECT_EQ(sha256_hex(bytes), "f3a25aa93aa2fbba28d79260535bbd6a5eb0fc1c24a8b0f04e12b484c1dfe363");
}

// Fed in pieces of every size, the digest is the one-shot digest.
TEST(Sha256, IncrementalEqualsOneShot) {
  std::vector<std::uint8_t> data(1000);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i * 7 + 3);
  std::uint8_t whole[firmware::kSha256Bytes];
  firmware::sha256(data.data(), data.size(), whole);
  for (std::size_t piece : {1, 3, 63, 64, 65, 200}) {
    firmware::Sha256 hash;
    for (std::size_t at = 0; at < data.size(); at += piece) hash.update(data.data() + at, std::min(piece, data.size() - at));
    std::uint8_t digest[firmware::kSha256Bytes];
    hash.finish(digest);
    EXPECT_EQ(hex(digest), hex(whole)) << piece;
  }
}

// Every prefix of a header program (a torn write) fails its check; the
// whole header passes; a revoke, even torn, revokes.
TEST(SlotHeader, TornWritesAndRevokesAreDetected) {
  firmware::SlotHeader header;
  header.sequence = 7;
  header.image_size = 1234;
  for (int i = 0; i < 32; ++i) header.digest[i] = static_cast<std::uint8_t>(i);
  std::uint8_t bytes[firmware::kSlotHeaderBytes - 4];
  firmware::encode_header(header, bytes);
  for (std::size_t written = 0; written < sizeof(bytes); ++written) {
    std::uint8_t flash[firmware::kSlotHeaderBytes];
    std::memset(flash, 0xFF, sizeof(flash));
    std::memcpy(flash, bytes, written);
    firmware::SlotHeader read;
    EXPECT_FALSE(firmware::decode_header(flash, read)) << written << " bytes written";
  }
  std::uint8_t flash[firmware::kSlotHeaderBytes];
  std::memset(flash, 0xFF, sizeof(flash));
  std::memcpy(flash, bytes, sizeof(bytes));
  firmware::SlotHeader read;
  ASSERT_TRUE(firmware::decode_header(flash, read));
  EXPECT_EQ(read.sequence, 7u);
  EXPECT_EQ(read.image_size, 1234u);
  flash[firmware::kSlotRevokeOffset + 1] = 0xF0;  // a revoke cut short
  EXPECT_FALSE(firmware::decode_header(flash, read));
}

TEST(TransferRecord, RoundTripsAndRejectsTornWrites) {
  firmware::TransferRecord record;
  record.transfer_id = 0xBEEF;
  record.image_size = 4096;
  record.digest[31] = 9;
  std::uint8_t bytes[firmware::kSlotRecordBytes];
  firmware::encode_record(record, bytes);
  firmware::TransferRecord read;
  ASSERT_TRUE(firmware::decode_record(bytes, read));
  EXPECT_EQ(read.transfer_id, 0xBEEF);
  EXPECT_EQ(read.image_size, 4096u);
  EXPECT_EQ(read.digest[31], 9);
  std::uint8_t torn[firmware::kSlotRecordBytes];
  std::memset(torn, 0xFF, sizeof(torn));
  std::memcpy(torn, bytes, sizeof(bytes) / 2);
  EXPECT_FALSE(firmware::decode_record(torn, read));
}

TEST(SimFlash, EraseSetsOnesProgramClearsBitsAndTakesPolls) {
  sim::SimFlash flash(256, 4, 64, {3, 1});
  const std::uint8_t first[2] = {0x0F, 0xF0};
  ASSERT_EQ(flash.start_program(10, first, 2), hal::FlashStatus::ok);
  EXPECT_EQ(flash.start_program(12, first, 2), hal::FlashStatus::busy);
  EXPECT_EQ(flash.poll(), hal::FlashStatus::busy);
  EXPECT_EQ(flash.poll(), hal::FlashStatus::ok);
  const std::uint8_t second[2] = {0xFF, 0x3C};
  ASSERT_EQ(flash.start_program(10, second, 2), hal::FlashStatus::ok);
  EXPECT_EQ(flash.read()[10], 0x0F);
  EXPECT_EQ(flash.read()[11], 0x30);  // only bits cleared
  EXPECT_EQ(flash.poll(), hal::FlashStatus::busy);
  EXPECT_EQ(flash.poll(), hal::FlashStatus::ok);
  EXPECT_EQ(flash.start_program(250, first, 8), hal::FlashStatus::bad_range);  // across a sector
  ASSERT_EQ(flash.start_erase(0), hal::FlashStatus::ok);
  EXPECT_EQ(flash.read()[10], 0xFF);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(flash.poll(), hal::FlashStatus::busy);
  EXPECT_EQ(flash.poll(), hal::FlashStatus::ok);
  EXPECT_EQ(flash.operations(), 3u);
}

TEST(SimFlash, PowerLossTearsTheKthOperation) {
  sim::SimFlash flash(256, 4, 64);
  std::vector<std::uint8_t> zeros(64, 0);
  flash.power_loss_at(2, sim::SimFlash::Cut::torn);
  ASSERT_EQ(flash.start_program(0, zeros.data(), 64), hal::FlashStatus::ok);
  while (flash.poll() == hal::FlashStatus::busy) {
  }
  ASSERT_EQ(flash.start_program(64, zeros.data(), 64), hal::FlashStatus::ok);
  EXPECT_TRUE(flash.power_lost());
  EXPECT_EQ(flash.read()[63], 0x00);
  EXPECT_EQ(flash.read()[64 + 31], 0x00);
  EXPECT_EQ(flash.read()[64 + 32], 0xFF);  // the second half never written
  EXPECT_EQ(flash.start_erase(0), hal::FlashStatus::failed);
  EXPECT_EQ(flash.read()[0], 0x00);
}

class ModelUpdateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    old_image = update_test_image(40, 1);
    new_image = update_test_image(60, 2);
    provision_slot(flash, 0, old_image, 1);
    board = std::make_unique<UpdateBoard>(flash, std::vector<std::uint8_t>{});
    ASSERT_EQ(board->runtime->state(), firmware::RuntimeState::run);
    ASSERT_EQ(board->active_image(), old_image);
    board->cycle();
  }

  // What must hold after any refused input: the old model runs and poses
  // keep coming.
  void expect_old_model_running() {
    const std::uint32_t poses = board->poses_seen;
    for (int i = 0; i < 3; ++i) board->cycle();
    EXPECT_EQ(board->runtime->state(), firmware::RuntimeState::run);
    EXPECT_EQ(board->active_image(), old_image);
    EXPECT_EQ(board->poses_seen, poses + 3);
  }

  // START a transfer and run until the runtime grants the first window.
  void start(UpdateSender& sender) {
    FrameQueue out;
    sender.start(out, board->now_ms());
    board->cycle(out.frames);
    for (int i = 0; i < 100 && board->runtime->model_update().state() != UpdateState::receiving; ++i) board->cycle();
    ASSERT_EQ(board->runtime->model_update().state(), UpdateState::receiving);
    board->take_reports();
  }

  std::vector<UpdateReason> reasons() { return test_support::report_reasons(board->take_reports()); }

  bool has_reason(UpdateReason reason) {
    for (UpdateReason r : reasons()) {
      if (r == reason) return true;
    }
    return false;
  }

  sim::SimFlash flash{1024, 64, 256};
  std::vector<std::uint8_t> old_image;
  std::vector<std::uint8_t> new_image;
  std::unique_ptr<UpdateBoard> board;
};

TEST_F(ModelUpdateTest, TransferCommitsWhilePosesKeepComing) {
  const std::uint32_t poses_before = board->poses_seen;
  const firmware::Pose pose_before = board->runtime->latest_pose().pose;
  SentImage sender_image(new_image);
  UpdateSender& sender = sender_image.sender;
  const int cycles = board->run_sender(sender, 5000);
  ASSERT_EQ(sender.outcome(), UpdateSender::Outcome::committed);
  // A pose in every cycle, the transfer's included.
  EXPECT_EQ(board->poses_seen, poses_before + std::uint32_t(cycles));
  EXPECT_EQ(board->runtime->state(), firmware::RuntimeState::run);
  EXPECT_EQ(board->runtime->model_update().active_slot(), 1);
  EXPECT_EQ(board->runtime->model_update().active_sequence(), 2u);
  EXPECT_EQ(board->active_image(), new_image);
  EXPECT_EQ(board->runtime->statistics().overruns, 0u);
  board->cycle();
  // The same cables, the new model's correction.
  EXPECT_GT((board->runtime->latest_pose().pose.position_mm - pose_before.position_mm).norm(), 1e-4f);
  std::printf("[ figures  ] %zu-byte image: %u blocks, %u frames, %d cycles\n", new_image.size(),
              sender.total_blocks(), sender.frames_sent(), cycles);

  // A reboot comes up on the new image; a rollback brings the old one back,
  // and so does the reboot after it.
  board->boot();
  EXPECT_EQ(board->active_image(), new_image);
  hal::CanFrame frame;
  firmware::protocol::encode(firmware::protocol::UpdateCommandFrame{firmware::protocol::UpdateCommand::rollback, 0, 0},
                             frame);
  board->cycle({frame});
  for (int i = 0; i < 200 && board->runtime->model_update().state() != UpdateState::committed; ++i) board->cycle();
  EXPECT_EQ(board->runtime->model_update().state(), UpdateState::committed);
  EXPECT_EQ(board->active_image(), old_image);
  EXPECT_EQ(board->runtime->state(), firmware::RuntimeState::run);
  board->boot();
  EXPECT_EQ(board->active_image(), old_image);
  // Nothing left to roll back to.
  board->take_reports();
  board->cycle({frame});
  EXPECT_TRUE(has_reason(UpdateReason::no_rollback_image));
}

TEST_F(ModelUpdateTest, CorruptedBlockIsRefusedAndResent) {
  SentImage sender_image(new_image);
  UpdateSender& sender = sender_image.sender;
  start(sender);
  FrameQueue out;
  sender.send_block(0, out);
  out.frames[1].data[3] ^= 0x10;
  board->cycle(out.frames);
  EXPECT_TRUE(has_reason(UpdateReason::corrupted));
  EXPECT_EQ(board->runtime->model_update().blocks_in_flash(), 0u);
  expect_old_model_running();
}

TEST_F(ModelUpdateTest, DuplicateBlockIsRefused) {
  SentImage sender_image(new_image);
  UpdateSender& sender = sender_image.sender;
  start(sender);
  FrameQueue out;
  sender.send_block(0, out);
  sender.send_block(0, out);
  board->cycle(out.frames);
  EXPECT_TRUE(has_reason(UpdateReason::duplicate));
  expect_old_model_running();
}

TEST_F(ModelUpdateTest, OutOfOrderBlockIsRefused) {
  SentImage sender_image(new_image);
  UpdateSender& sender = sender_image.sender;
  start(sender);
  FrameQueue out;
  sender.send_block(2, out);
  board->cycle(out.frames);
  EXPECT_TRUE(has_reason(UpdateReason::out_of_order));
  EXPECT_EQ(board->runtime->model_update().blocks_in_flash(), 0u);
  expect_old_model_running();
}

TEST_F(ModelUpdateTest, MissingDataAndMissingBlocksAreRefused) {
  SentImage sender_image(new_image);
  UpdateSender& sender = sender_image.sender;
  start(sender);
  FrameQueue out;
  sender.send_block(0, out);
  out.frames.pop_back();  // the block's last data frame lost
  sender.send_block(1, out);
  board->cycle(out.frames);
  EXPECT_TRUE(has_reason(UpdateReason::missing_block));
  // COMMIT with blocks missing.
  hal::CanFrame commit;
  firmware::protocol::encode(
      firmware::protocol::UpdateCommandFrame{firmware::protocol::UpdateCommand::commit, sender.transfer_id(), 0}, commit);
  board->cycle({commit});
  EXPECT_TRUE(has_reason(UpdateReason::missing_block));
  expect_old_model_running();
}

TEST_F(ModelUpdateTest, TransferLeftHalfWayTimesOutAndResumes) {
  SentImage sender_image(new_image);
  UpdateSender& sender = sender_image.sender;
  start(sender);
  FrameQueue out;
  for (std::uint32_t b = 0; b < 4; ++b) sender.send_block(b, out);
  board->cycle(out.frames);
  for (std::uint32_t i = 0; i < firmware::kUpdateTimeoutCycles + 2; ++i) board->runtime->run_cycle(board->timer.wait_next());
  board->cycle();
  EXPECT_TRUE(has_reason(UpdateReason::timeout));
  EXPECT_EQ(board->runtime->model_update().state(), UpdateState::failed);
  EXPECT_EQ(board->runtime->model_update().blocks_in_flash(), 4u);
  expect_old_model_running();
  // START again resumes after the four blocks in flash.
  SentImage again_image(new_image);
  UpdateSender& again = again_image.sender;
  board->run_sender(again, 5000);
  EXPECT_EQ(again.outcome(), UpdateSender::Outcome::committed);
  EXPECT_LT(again.frames_sent(), sender.frames_sent() + (again.total_blocks() - 3) * 9 + 20);
  EXPECT_EQ(board->active_image(), new_image);
}

TEST_F(ModelUpdateTest, SecondTransferOverTheFirstIsRefused) {
  SentImage sender_image(new_image);
  UpdateSender& sender = sender_image.sender;
  start(sender);
  SentImage other_image(update_test_image(30, 3));
  UpdateSender& other = other_image.sender;
  FrameQueue out;
  other.start(out, board->now_ms());
  board->cycle(out.frames);
  EXPECT_TRUE(has_reason(UpdateReason::busy));
  EXPECT_EQ(board->runtime->model_update().state(), UpdateState::receiving);
  expect_old_model_running();
}

// Blocks whose SHA-256 is not the one START announced: refused at COMMIT,
// before anything is made active.
TEST_F(ModelUpdateTest, DigestMismatchIsRefusedAtCommit) {
  SentImage sender_image(new_image);
  UpdateSender& sender = sender_image.sender;
  FrameQueue out;
  sender.start(out, board->now_ms());
  out.frames[0].data[1] ^= 0x01;  // the first digest byte, as announced
  board->cycle(out.frames);
  for (int i = 0; i < 100 && board->runtime->model_update().state() != UpdateState::receiving; ++i) board->cycle();
  ASSERT_EQ(board->runtime->model_update().state(), UpdateState::receiving);
  std::uint32_t next = 0;
  for (int i = 0; i < 2000 && board->runtime->model_update().blocks_in_flash() < sender.total_blocks(); ++i) {
    out.frames.clear();
    while (next < sender.total_blocks() &&
           next < board->runtime->model_update().blocks_in_flash() + firmware::kUpdateWindowBlocks) {
      sender.send_block(next++, out);
    }
    board->cycle(out.frames);
  }
  board->take_reports();
  hal::CanFrame commit;
  firmware::protocol::encode(
      firmware::protocol::UpdateCommandFrame{firmware::protocol::UpdateCommand::commit, sender.transfer_id(), 0}, commit);
  board->cycle({commit});
  for (int i = 0; i < 50; ++i) board->cycle();
  EXPECT_TRUE(has_reason(UpdateReason::digest_mismatch));
  EXPECT_EQ(board->runtime->model_update().state(), UpdateState::failed);
  expect_old_model_running();
  board->boot();
  EXPECT_EQ(board->active_image(), old_image);
}

// Images the runtime refuses at the end of a transfer, or at its start.
class RefusedImageTest : public ModelUpdateTest {
 protected:
  void expect_refused(const std::vector<std::uint8_t>& image, UpdateReason reason) {
    SentImage sender_image(image);
  UpdateSender& sender = sender_image.sender;
    board->run_sender(sender, 5000);
    EXPECT_EQ(sender.outcome(), UpdateSender::Outcome::refused);
    EXPECT_EQ(sender.refusal(), reason) << "reason " << int(sender.refusal());
    expect_old_model_running();
    board->boot();
    EXPECT_EQ(board->active_image(), old_image);
  }
};

TEST_F(RefusedImageTest, AnotherGeometry) { expect_refused(update_test_image(40, 4, 2, 150.0), UpdateReason::wrong_geometry); }

TEST_F(RefusedImageTest, AnotherSegmentCount) {
  expect_refused(update_test_image(40, 4, 3), UpdateReason::wrong_segment_count);
}

TEST_F(RefusedImageTest, AnotherFormatVersion) {
  std::vector<std::uint8_t> image = new_image;
  image[model::image_field::version_major.offset] = 9;
  expect_refused(image, UpdateReason::unsupported_version);
}

TEST_F(RefusedImageTest, CorruptedImage) {
  std::vector<std::uint8_t> image = new_image;
  image[image.size() / 2] ^= 0x01;  // its own CRC no longer matches
  expect_refused(image, UpdateReason::image_invalid);
}

TEST_F(RefusedImageTest, TooLargeForTheSlot) {
  std::vector<std::uint8_t> image(firmware::slot_geometry(flash, 1).image_capacity() + 8, 0);
  std::memcpy(image.data(), new_image.data(), 64);
  expect_refused(image, UpdateReason::too_large);
}

// A payload model of 500 points (3 work units a point) leaves IK only its
// floor, and a target streamed every cycle keeps IK running: the update's
// verification gets nothing beside IK and must still finish, in the turns
// it gets every kUpdateTurnEveryCyclesWhileSolving cycles.
TEST(ModelUpdateWhileSolving, VerificationFinishesUnderAStreamOfTargets) {
  sim::SimFlash flash{1024, 64, 256};
  SyntheticModelOptions options;
  options.training_points = 500;
  options.seed = 3;
  options.payload_input = true;
  training::TrainedModel heavy = synthetic_trained_model(options);
  for (int k = 0; k < 6; ++k) {
    heavy.output_mean[k] *= k < 3 ? 0.1 : 0.001;
    heavy.output_scale[k] *= k < 3 ? 0.1 : 0.001;
  }
  provision_slot(flash, 0, exporting::write_image(heavy), 1);
  UpdateBoard board(flash, {});
  ASSERT_EQ(board.runtime->state(), firmware::RuntimeState::run);
  board.cycle();
  const firmware::Pose start_pose = board.runtime->latest_pose().pose;

  SentImage sender_image(update_test_image(60, 2));
  UpdateSender& sender = sender_image.sender;
  FrameQueue out;
  sender.start(out, board.now_ms());
  int cycles = 0, cycles_verifying = 0, cycles_verifying_with_ik = 0;
  bool starved = false;
  while (cycles < 20000 && sender.outcome() == UpdateSender::Outcome::running) {
    sender.pump(board.now_ms(), out, 44);
    // A TRACKING position target every cycle, circling the start pose.
    hal::CanFrame frame;
    const double angle = 0.002 * cycles;
    firmware::protocol::encode(firmware::protocol::TargetPositionXy{start_pose.position_mm.x() + 2.0 * std::cos(angle),
                                                                    start_pose.position_mm.y() + 2.0 * std::sin(angle)},
                               frame);
    out.frames.push_back(frame);
    firmware::protocol::encode(firmware::protocol::TargetPositionZ{start_pose.position_mm.z(),
                                                                   firmware::protocol::TargetMode::position, true,
                                                                   static_cast<std::uint8_t>(cycles)},
                               frame);
    out.frames.push_back(frame);
    const bool verifying = board.runtime->model_update().verifying();
    board.cycle(out.frames);
    out.frames.clear();
    if (verifying) {
      ++cycles_verifying;
      if (board.runtime->ik_running()) ++cycles_verifying_with_ik;
      starved = starved || board.runtime->ik_units_per_cycle() < firmware::kMinIkUnitsPerCycle +
                                                                      firmware::kUpdateStepUnits +
                                                                      firmware::kUpdateHashUnitsPer64Bytes;
    }
    for (const hal::CanFrame& report : board.take_reports()) sender.on_report(report, board.now_ms(), out);
    ++cycles;
  }
  // The premise: IK ran through the verification, at a share that left the
  // update nothing.
  ASSERT_GT(cycles_verifying, 0);
  EXPECT_EQ(cycles_verifying_with_ik, cycles_verifying);
  EXPECT_TRUE(starved);
  EXPECT_EQ(sender.outcome(), UpdateSender::Outcome::committed);
  EXPECT_EQ(board.runtime->statistics().overruns, 0u);
  std::printf("[ figures  ] verification under a target stream: %d cycles of %d\n", cycles_verifying, cycles);
}

}  // namespace
}  // namespace cdcr::test_support
