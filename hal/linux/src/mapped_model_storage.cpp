#include "cdcr/linux/mapped_model_storage.hpp"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace cdcr::linux_host {

MappedModelStorage::~MappedModelStorage() { unmap(); }

void MappedModelStorage::unmap() {
  if (bytes_ != nullptr) munmap(const_cast<std::uint8_t*>(bytes_), size_bytes_);
  bytes_ = nullptr;
  size_bytes_ = 0;
}

bool MappedModelStorage::map_file(const std::string& path, std::string& error) {
  unmap();
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    error = "cannot open " + path + ": " + std::strerror(errno);
    return false;
  }
  struct stat info {};
  if (fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
    error = path + ": not a regular file";
    close(fd);
    return false;
  }
  if (info.st_size == 0) {
    close(fd);
    return true;
  }
  void* mapping = mmap(nullptr, std::size_t(info.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
  const int map_errno = errno;
  // The mapping keeps its own reference to the file.
  close(fd);
  if (mapping == MAP_FAILED) {
    error = "cannot map " + path + ": " + std::strerror(map_errno);
    return false;
  }
  bytes_ = static_cast<const std::uint8_t*>(mapping);
  size_bytes_ = std::size_t(info.st_size);
  return true;
}

}  // namespace cdcr::linux_host
