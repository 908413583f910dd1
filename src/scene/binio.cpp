#include "scene/binio.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <memory>

#include "core/parallel.hpp"

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

namespace {
constexpr uint64_t kSeed = 0x243F6A8885A308D3ull, kWordMul = 0x9E3779B97F4A7C15ull;

uint64_t step(uint64_t h, const uint8_t* p) {
  uint64_t w;
  std::memcpy(&w, p, 8);
  h = (h ^ w) * kWordMul;
  return h ^ (h >> 29);
}

uint64_t finish(uint64_t h, const uint8_t* p, size_t rest) {
  uint64_t tail = 0;
  if (rest) std::memcpy(&tail, p, rest);  // no bytes: p may be null
  h = (h ^ tail) * 0xBF58476D1CE4E5B9ull;
  return h ^ (h >> 31);
}

// checksum64 of the four pieces of n bytes at p, p + n, p + 2n, p + 3n: their chains are independent, so
// one thread runs them side by side (the multiplies overlap) at about four times one chain's speed.
void checksum64x4(const uint8_t* p, size_t n, uint64_t* out) {
  uint64_t h[4] = {kSeed ^ n, kSeed ^ n, kSeed ^ n, kSeed ^ n};
  size_t i = 0;
  for (; i + 8 <= n; i += 8)
    for (size_t j = 0; j < 4; ++j) h[j] = step(h[j], p + j * n + i);
  for (size_t j = 0; j < 4; ++j) out[j] = finish(h[j], p + j * n + i, n - i);
}
}  // namespace

uint64_t checksum64(std::span<const uint8_t> data) {
  uint64_t h = kSeed ^ data.size();
  size_t i = 0;
  for (; i + 8 <= data.size(); i += 8) h = step(h, data.data() + i);
  return finish(h, data.data() + i, data.size() - i);
}

uint64_t pieceChecksum64(std::span<const uint8_t> data, unsigned threads) {
  std::vector<uint64_t> sums((data.size() + kChecksumPiece - 1) / kChecksumPiece);
  const size_t quads = data.size() / (4 * kChecksumPiece);  // runs of four whole pieces; the rest one by one
  parallelFor(quads + sums.size() - 4 * quads, threads, [&](size_t job) {
    if (job < quads) return checksum64x4(data.data() + job * 4 * kChecksumPiece, kChecksumPiece, &sums[job * 4]);
    const size_t i = 4 * quads + (job - quads);
    sums[i] = checksum64(data.subspan(i * kChecksumPiece, std::min(kChecksumPiece, data.size() - i * kChecksumPiece)));
  });
  return checksum64({reinterpret_cast<const uint8_t*>(sums.data()), sums.size() * 8});
}

}  // namespace rtr
