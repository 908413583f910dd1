#include "scene/binio.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <memory>

namespace rtr {
namespace {
struct FileCloser {
  void operator()(std::FILE* f) const { if (f) std::fclose(f); }
};
}  // namespace

MappedFile::MappedFile(const std::filesystem::path& file) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw fileError(file.string(), "", std::string("cannot open: ") + std::strerror(errno));
  struct stat st {};
  const bool ok = ::fstat(fd, &st) == 0;
  const int err = errno;
  if (!ok || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw fileError(file.string(), "", ok ? "not a regular file" : std::string("cannot stat: ") + std::strerror(err));
  }
  size_ = size_t(st.st_size);
  if (size_ > 0) {  // an empty file maps nothing: its span is empty
    data_ = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (data_ == MAP_FAILED) {
      data_ = nullptr;
      const int mapErr = errno;
      ::close(fd);
      throw fileError(file.string(), "", std::string("cannot map: ") + std::strerror(mapErr));
    }
    ::madvise(data_, size_, MADV_SEQUENTIAL);
  }
  ::close(fd);  // the mapping keeps the file
}

MappedFile::~MappedFile() {
  if (data_) ::munmap(data_, size_);
}

std::vector<uint8_t> readFileBytes(const std::filesystem::path& file) {
  std::unique_ptr<std::FILE, FileCloser> f(std::fopen(file.c_str(), "rb"));
  if (!f) throw fileError(file.string(), "", std::string("cannot open: ") + std::strerror(errno));
  std::vector<uint8_t> out;
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  if (!ec) out.reserve(size);
  uint8_t buf[1 << 16];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, f.get())) > 0;) out.insert(out.end(), buf, buf + n);
  if (std::ferror(f.get())) throw fileError(file.string(), "", "read error");
  return out;
}

uint64_t checksum64(std::span<const uint8_t> data) {
  uint64_t h = 0x243F6A8885A308D3ull ^ data.size();
  size_t i = 0;
  for (; i + 8 <= data.size(); i += 8) {
    uint64_t w;
    std::memcpy(&w, data.data() + i, 8);
    h = (h ^ w) * 0x9E3779B97F4A7C15ull;
    h ^= h >> 29;
  }
  uint64_t tail = 0;
  std::memcpy(&tail, data.data() + i, data.size() - i);
  h = (h ^ tail) * 0xBF58476D1CE4E5B9ull;
  h ^= h >> 31;
  return h;
}

}  // namespace rtr
