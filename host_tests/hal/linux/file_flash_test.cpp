// The file-backed flash of the Linux host: a new file is erased; erase sets
// a sector to 0xFF and leaves the others; a program clears bits only; every
// operation stays in one sector and within the file; what was written is in
// the file after a reopen.

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include <cdcr/linux/file_flash.hpp>

namespace cdcr::linux_host {
namespace {

namespace fs = std::filesystem;
constexpr std::uint32_t kSector = FileFlash::kSectorBytes;

hal::FlashStatus finish(FileFlash& flash) {
  hal::FlashStatus status;
  while ((status = flash.poll()) == hal::FlashStatus::busy) {
  }
  return status;
}

class FileFlashTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "cdcr_file_flash_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir = pattern;
    std::string error;
    ASSERT_TRUE(flash.open_directory((dir / "flash").string(), error)) << error;
  }
  void TearDown() override { fs::remove_all(dir); }

  hal::FlashStatus program(std::uint32_t offset, std::initializer_list<std::uint8_t> bytes) {
    const hal::FlashStatus started = flash.start_program(offset, bytes.begin(), std::uint32_t(bytes.size()));
    return started == hal::FlashStatus::ok ? finish(flash) : started;
  }

  fs::path dir;
  FileFlash flash;
};

TEST_F(FileFlashTest, ANewFileIsErased) {
  EXPECT_EQ(fs::file_size(dir / "flash" / "flash.bin"), std::uintmax_t(kSector) * FileFlash::kSectorCount);
  for (std::uint32_t i = 0; i < kSector * FileFlash::kSectorCount; ++i) ASSERT_EQ(flash.read()[i], 0xFF) << i;
}

TEST_F(FileFlashTest, AProgramClearsBitsOnly) {
  ASSERT_EQ(program(kSector + 10, {0xF0, 0x0F}), hal::FlashStatus::ok);
  EXPECT_EQ(flash.read()[kSector + 10], 0xF0);
  EXPECT_EQ(flash.read()[kSector + 11], 0x0F);
  EXPECT_EQ(flash.read()[kSector + 12], 0xFF);
  ASSERT_EQ(program(kSector + 10, {0x3C, 0x3C}), hal::FlashStatus::ok);
  EXPECT_EQ(flash.read()[kSector + 10], 0x30);
  EXPECT_EQ(flash.read()[kSector + 11], 0x0C);
}

TEST_F(FileFlashTest, AnEraseSetsItsSectorOnly) {
  ASSERT_EQ(program(kSector - 1, {0x00}), hal::FlashStatus::ok);
  ASSERT_EQ(program(kSector, {0x00}), hal::FlashStatus::ok);
  ASSERT_EQ(program(2 * kSector - 1, {0x00}), hal::FlashStatus::ok);
  ASSERT_EQ(flash.start_erase(1), hal::FlashStatus::ok);
  ASSERT_EQ(finish(flash), hal::FlashStatus::ok);
  EXPECT_EQ(flash.read()[kSector - 1], 0x00);
  EXPECT_EQ(flash.read()[kSector], 0xFF);
  EXPECT_EQ(flash.read()[2 * kSector - 1], 0xFF);
}

TEST_F(FileFlashTest, OperationsStayInOneSectorOfTheFile) {
  const std::uint8_t bytes[FileFlash::kMaxProgramBytes + 1] = {};
  EXPECT_EQ(flash.start_program(kSector - 1, bytes, 2), hal::FlashStatus::bad_range);
  EXPECT_EQ(flash.start_program(0, bytes, 0), hal::FlashStatus::bad_range);
  EXPECT_EQ(flash.start_program(0, bytes, FileFlash::kMaxProgramBytes + 1), hal::FlashStatus::bad_range);
  EXPECT_EQ(flash.start_program(kSector * FileFlash::kSectorCount, bytes, 1), hal::FlashStatus::bad_range);
  EXPECT_EQ(flash.start_erase(FileFlash::kSectorCount), hal::FlashStatus::bad_range);
  EXPECT_EQ(flash.read()[kSector - 1], 0xFF);
}

TEST_F(FileFlashTest, TheFileKeepsWhatWasWritten) {
  ASSERT_EQ(program(3 * kSector + 5, {0x12, 0x34}), hal::FlashStatus::ok);
  FileFlash reopened;
  std::string error;
  ASSERT_TRUE(reopened.open_directory((dir / "flash").string(), error)) << error;
  EXPECT_EQ(reopened.read()[3 * kSector + 5], 0x12);
  EXPECT_EQ(reopened.read()[3 * kSector + 6], 0x34);
}

TEST(FileFlashUnopened, RefusesEveryOperation) {
  FileFlash flash;
  const std::uint8_t byte = 0;
  EXPECT_EQ(flash.start_erase(0), hal::FlashStatus::failed);
  EXPECT_EQ(flash.start_program(0, &byte, 1), hal::FlashStatus::failed);
}

}  // namespace
}  // namespace cdcr::linux_host
