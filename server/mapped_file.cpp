#include "server/mapped_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace meshstream::server {
namespace {

class MappedFile final : public StreamBytes {
 public:
  MappedFile(void* data, size_t size) : data_(data), size_(size) {}
  ~MappedFile() override { ::munmap(data_, size_); }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  std::span<const uint8_t> bytes() const override {
    return {static_cast<const uint8_t*>(data_), size_};
  }

 private:
  void* data_;
  size_t size_;
};

class OwnedBytes final : public StreamBytes {
 public:
  explicit OwnedBytes(std::vector<uint8_t> bytes) : bytes_(std::move(bytes)) {}
  std::span<const uint8_t> bytes() const override { return bytes_; }

 private:
  std::vector<uint8_t> bytes_;
};

}  // namespace

Result<std::shared_ptr<const StreamBytes>> map_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return make_error(ErrorCode::kIo, path + ": cannot open: " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int err = errno;
    ::close(fd);
    return make_error(ErrorCode::kIo, path + ": cannot stat: " + std::strerror(err));
  }
  if (st.st_size == 0) {
    ::close(fd);
    return make_error(ErrorCode::kInvalidArgument, path + ": empty file");
  }
  void* data = ::mmap(nullptr, static_cast<size_t>(st.st_size), PROT_READ, MAP_SHARED, fd, 0);
  const int err = errno;
  ::close(fd);  // the mapping keeps the file alive
  if (data == MAP_FAILED)
    return make_error(ErrorCode::kIo, path + ": cannot map: " + std::strerror(err));
  return std::shared_ptr<const StreamBytes>(
      std::make_shared<MappedFile>(data, static_cast<size_t>(st.st_size)));
}

std::shared_ptr<const StreamBytes> own_bytes(std::vector<uint8_t> bytes) {
  return std::make_shared<OwnedBytes>(std::move(bytes));
}

}  // namespace meshstream::server
