#include "core/input_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <new>

#include "core/error.hpp"

namespace rtr {
namespace {

const char* kindOf(mode_t m) {
  return S_ISDIR(m)    ? "a folder"
         : S_ISFIFO(m) ? "a FIFO (named pipe)"
         : S_ISCHR(m)  ? "a character device"
         : S_ISBLK(m)  ? "a block device"
         : S_ISSOCK(m) ? "a socket"
                       : "not a regular file";
}

std::string mb(uint64_t bytes) { return std::to_string((bytes + (1 << 20) - 1) >> 20) + " MB"; }

}  // namespace

InputFile::InputFile(const std::filesystem::path& file, const char* what) : name_(file.string()), what_(what) {
  // stat first, so that a device is never opened at all; O_NONBLOCK so that a FIFO swapped in meanwhile
  // cannot block the open either; fstat decides.
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) throw fileError(name_, "", "cannot open " + what_ + ": " + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw fileError(name_, "", std::string(kindOf(st.st_mode)) + ", not a regular file");
  fd_ = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd_ < 0) throw fileError(name_, "", "cannot open " + what_ + ": " + std::strerror(errno));
  if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
    const std::string why = S_ISREG(st.st_mode) ? std::strerror(errno) : kindOf(st.st_mode);
    ::close(fd_);
    throw fileError(name_, "", why + ", not a regular file");
  }
  ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) & ~O_NONBLOCK);
  size_ = uint64_t(st.st_size);
}

InputFile::~InputFile() {
  if (fd_ >= 0) ::close(fd_);
}

size_t InputFile::read(void* dst, size_t n) {
  n = size_t(std::min<uint64_t>(n, size_ - std::min(pos_, size_)));
  size_t got = 0;
  while (got < n) {
    const ssize_t k = ::read(fd_, static_cast<char*>(dst) + got, n - got);
    if (k < 0 && errno == EINTR) continue;
    if (k < 0) throw fileError(name_, "byte " + std::to_string(pos_ + got), std::string("read error: ") + std::strerror(errno));
    if (k == 0) break;  // shrank meanwhile: its end is the end
    got += size_t(k);
  }
  pos_ += got;
  return got;
}

std::string InputFile::readAll(uint64_t maxBytes) {
  if (size_ > maxBytes)
    throw fileError(name_, "", what_ + " of " + std::to_string(size_) + " bytes; the limit is " + mb(maxBytes));
  std::string out;
  try {
    out.resize(size_t(size_));
  } catch (const std::bad_alloc&) { throw fileError(name_, "", "out of memory while reading it: needs " + mb(size_)); }
  out.resize(read(out.data(), out.size()));
  return out;
}

std::string readInputFile(const std::filesystem::path& file, const char* what, uint64_t maxBytes) {
  return InputFile(file, what).readAll(maxBytes);
}

MappedFile::MappedFile(const std::filesystem::path& file, const char* what) {
  const InputFile in(file, what);
  size_ = size_t(in.size());
  if (size_ == 0) return;  // an empty file maps nothing: its span is empty
  data_ = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, in.fd(), 0);
  if (data_ == MAP_FAILED) {
    data_ = nullptr;
    const int err = errno;
    throw fileError(in.name(), "",
                    err == ENOMEM ? "out of memory (address space) while mapping its " + mb(size_)
                                  : std::string("cannot map: ") + std::strerror(err));
  }
  ::madvise(data_, size_, MADV_SEQUENTIAL);
}  // the mapping keeps the file

MappedFile::~MappedFile() {
  if (data_) ::munmap(data_, size_);
}

}  // namespace rtr
