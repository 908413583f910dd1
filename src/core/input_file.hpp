#pragma once
// Every input file the tools read is opened here, so that none can block, grow without end or be read
// past a limit: anything but a regular file (a FIFO, a device such as /dev/zero, a folder) is refused with
// a message naming it, before a byte is read and without waiting (the open is non-blocking), and the size
// is known before reading, so each reader checks what the file declares against it (docs/files-and-cli.md).
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

namespace rtr {

class InputFile {
 public:
  // `what` names the file's role in messages ("material library", "SPIR-V file"). Throws rtr::Error.
  explicit InputFile(const std::filesystem::path& file, const char* what = "file");
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  const std::string& name() const { return name_; }
  uint64_t size() const { return size_; }  // at open
  int fd() const { return fd_; }
  // Up to n bytes, fewer only at the end (or past size(): a file that grew is read no further).
  size_t read(void* dst, size_t n);
  // The whole file, refused before reading when over `maxBytes` ("FILE: WHAT of N bytes; the limit is M").
  std::string readAll(uint64_t maxBytes);

 private:
  std::string name_, what_;
  int fd_ = -1;
  uint64_t size_ = 0, pos_ = 0;
};

// Shorthand: InputFile(file, what).readAll(maxBytes).
std::string readInputFile(const std::filesystem::path& file, const char* what, uint64_t maxBytes);

// A regular file's bytes mapped read-only (opened through InputFile): no copy, pages come in as a decoder
// reads them, so a header that is wrong is found without reading the rest. Our tools replace files by
// rename, never rewrite them in place (core/atomic_file), so the mapping of a file being replaced keeps
// the old bytes. Throws rtr::Error naming the file.
class MappedFile {
 public:
  explicit MappedFile(const std::filesystem::path& file, const char* what = "file");
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  std::span<const uint8_t> bytes() const { return {static_cast<const uint8_t*>(data_), size_}; }

 private:
  void* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace rtr
