#pragma once
// The flash on a Linux host: one file in a directory (DIR/flash.bin), mapped
// read-only for the runtime to parse in place, written by a worker thread so
// that the runtime's cycle never waits on the disk. An operation reports
// done only after fdatasync(): what the runtime acknowledged survives a
// SIGKILL or a power loss. Same semantics as a NOR flash (hal/flash.hpp):
// erase writes 0xFF, program ANDs its bytes into what is there, applied by
// the HAL's one NOR model (hal/nor_flash_model.hpp) to a copy of the sector.

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <cdcr/hal/flash.hpp>

namespace cdcr::linux_host {

class FileFlash final : public hal::Flash {
 public:
  static constexpr std::uint32_t kSectorBytes = 4096;
  // Two slots of a metadata sector and 32 image sectors (128 KiB) each.
  static constexpr std::uint32_t kSectorCount = 2 * 33;
  static constexpr std::uint32_t kMaxProgramBytes = 256;

  FileFlash() = default;
  ~FileFlash();
  FileFlash(const FileFlash&) = delete;
  FileFlash& operator=(const FileFlash&) = delete;

  // Opens DIR/flash.bin, creating the directory's file erased if missing.
  // On failure returns false and describes the cause in `error`.
  bool open_directory(const std::string& directory, std::string& error);

  std::uint32_t sector_bytes() const override { return kSectorBytes; }
  std::uint32_t sector_count() const override { return kSectorCount; }
  std::uint32_t max_program_bytes() const override { return kMaxProgramBytes; }
  const std::uint8_t* read() const override { return mapping_; }

  hal::FlashStatus start_erase(std::uint32_t sector) override;
  hal::FlashStatus start_program(std::uint32_t offset, const std::uint8_t* data, std::uint32_t size) override;
  hal::FlashStatus poll() override;

 private:
  void work();
  hal::FlashStatus start(std::uint32_t offset, const std::uint8_t* data, std::uint32_t size, bool erase);

  int fd_ = -1;
  const std::uint8_t* mapping_ = nullptr;
  std::thread worker_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool pending_ = false;  // an operation handed to the worker, not yet done
  std::atomic<bool> running_{false};
  std::atomic<bool> failed_{false};
  std::uint32_t offset_ = 0;
  std::uint32_t size_ = 0;
  bool erase_ = false;
  std::uint8_t data_[kSectorBytes] = {};
};

}  // namespace cdcr::linux_host
