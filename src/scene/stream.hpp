#pragma once
// Sequential byte sources for the text parsers: a plain file or a zstd stream decompressed on the fly,
// so a large OBJ never sits in memory whole.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

namespace rtr {

class ByteSource {
 public:
  virtual ~ByteSource() = default;
  // Fills up to n bytes; returns 0 only at the end. Throws rtr::Error naming the file on I/O or codec faults.
  virtual size_t read(char* dst, size_t n) = 0;
  // Bytes consumed from the file so far (compressed bytes for zstd) and the file size, for progress.
  virtual uint64_t consumed() const = 0;
  virtual uint64_t fileSize() const = 0;
};

// True for .obj.zst, .obj-zstd and .zst names.
bool isZstdName(const std::filesystem::path& file);
// Opens `file`, decompressing when its name says zstd (a series of sized frames on `threads`, 0: all
// cores). Throws rtr::Error naming the file.
std::unique_ptr<ByteSource> openSource(const std::filesystem::path& file, unsigned threads = 0);
// A source over memory (tests, fuzzing); `zstd` decompresses it.
std::unique_ptr<ByteSource> memorySource(std::string data, std::string name, bool zstd = false, unsigned threads = 0);

}  // namespace rtr
