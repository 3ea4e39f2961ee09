#include "cdcr/linux/file_flash.hpp"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cdcr/hal/nor_flash_model.hpp>

namespace cdcr::linux_host {

namespace {
constexpr std::size_t kFileBytes = std::size_t(FileFlash::kSectorBytes) * FileFlash::kSectorCount;

// A copy of one sector of the file, changed under the NOR rules every flash
// of the project shares; the worker writes the changed bytes back.
class SectorCopy final : public hal::NorFlashModel {
 public:
  explicit SectorCopy(std::uint8_t* bytes)
      : NorFlashModel(bytes, FileFlash::kSectorBytes, 1, FileFlash::kMaxProgramBytes, hal::NorFlashTiming{0, 0}) {}
};
}  // namespace

FileFlash::~FileFlash() {
  if (worker_.joinable()) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    worker_.join();
  }
  if (mapping_ != nullptr) munmap(const_cast<std::uint8_t*>(mapping_), kFileBytes);
  if (fd_ >= 0) close(fd_);
}

bool FileFlash::open_directory(const std::string& directory, std::string& error) {
  if (mkdir(directory.c_str(), 0755) != 0 && errno != EEXIST) {
    error = "cannot create " + directory + ": " + std::strerror(errno);
    return false;
  }
  const std::string path = directory + "/flash.bin";
  fd_ = open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd_ < 0 && errno == ENOENT) {
    // A new flash is erased: written whole under a temporary name, then
    // renamed, so a crash never leaves a short file.
    const std::string temporary = path + ".new";
    const int fd = open(temporary.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) {
      error = "cannot create " + temporary + ": " + std::strerror(errno);
      return false;
    }
    std::vector<std::uint8_t> erased(kFileBytes, 0xFF);
    const bool written = write(fd, erased.data(), erased.size()) == static_cast<ssize_t>(erased.size()) &&
                         fsync(fd) == 0;
    close(fd);
    if (!written || rename(temporary.c_str(), path.c_str()) != 0) {
      error = "cannot write " + path + ": " + std::strerror(errno);
      return false;
    }
    const int dir = open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir >= 0) {
      fsync(dir);
      close(dir);
    }
    fd_ = open(path.c_str(), O_RDWR | O_CLOEXEC);
  }
  if (fd_ < 0) {
    error = "cannot open " + path + ": " + std::strerror(errno);
    return false;
  }
  struct stat info {};
  if (fstat(fd_, &info) != 0 || std::size_t(info.st_size) != kFileBytes) {
    error = path + ": not a flash file of " + std::to_string(kFileBytes) + " bytes";
    return false;
  }
  void* mapping = mmap(nullptr, kFileBytes, PROT_READ, MAP_SHARED, fd_, 0);
  if (mapping == MAP_FAILED) {
    error = "cannot map " + path + ": " + std::strerror(errno);
    return false;
  }
  mapping_ = static_cast<const std::uint8_t*>(mapping);
  worker_ = std::thread([this] { work(); });
  return true;
}

hal::FlashStatus FileFlash::start(std::uint32_t offset, const std::uint8_t* data, std::uint32_t size, bool erase) {
  if (fd_ < 0) return hal::FlashStatus::failed;
  if (running_.load()) return hal::FlashStatus::busy;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    offset_ = offset;
    size_ = size;
    erase_ = erase;
    if (!erase) std::memcpy(data_, data, size);
    pending_ = true;
    failed_ = false;
    running_ = true;
  }
  wake_.notify_one();
  return hal::FlashStatus::ok;
}

hal::FlashStatus FileFlash::start_erase(std::uint32_t sector) {
  if (sector >= kSectorCount) return hal::FlashStatus::bad_range;
  return start(sector * kSectorBytes, nullptr, kSectorBytes, true);
}

hal::FlashStatus FileFlash::start_program(std::uint32_t offset, const std::uint8_t* data, std::uint32_t size) {
  if (size == 0 || size > kMaxProgramBytes || offset >= kFileBytes || size > kFileBytes - offset ||
      offset / kSectorBytes != (offset + size - 1) / kSectorBytes) {
    return hal::FlashStatus::bad_range;
  }
  return start(offset, data, size, false);
}

hal::FlashStatus FileFlash::poll() {
  if (running_.load()) return hal::FlashStatus::busy;
  return failed_.load() ? hal::FlashStatus::failed : hal::FlashStatus::ok;
}

void FileFlash::work() {
  std::uint8_t bytes[kSectorBytes];
  for (;;) {
    std::unique_lock<std::mutex> lock(mutex_);
    wake_.wait(lock, [this] { return stop_ || pending_; });
    if (stop_) return;
    pending_ = false;
    const std::uint32_t offset = offset_;
    const std::uint32_t size = size_;
    const std::uint32_t sector_start = offset / kSectorBytes * kSectorBytes;
    std::memcpy(bytes, mapping_ + sector_start, kSectorBytes);
    SectorCopy sector(bytes);
    const hal::FlashStatus applied =
        erase_ ? sector.start_erase(0) : sector.start_program(offset - sector_start, data_, size);
    lock.unlock();
    const bool ok = applied == hal::FlashStatus::ok &&
                    pwrite(fd_, bytes + (offset - sector_start), size, off_t(offset)) == static_cast<ssize_t>(size) &&
                    fdatasync(fd_) == 0;
    failed_ = !ok;
    running_ = false;
  }
}

}  // namespace cdcr::linux_host
