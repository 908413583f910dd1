#pragma once
// Little-endian binary encoding helpers for the baked formats: an appending writer and a bounds-checked
// reader whose every fault names the file, the byte offset and what was wrong.
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/atomic_file.hpp"  // writeFileAtomic: every baked file is written through it
#include "core/error.hpp"
#include "core/input_file.hpp"  // MappedFile
#include "core/view_or_vector.hpp"

namespace rtr {

static_assert(std::endian::native == std::endian::little, "the baked formats are little-endian");

// Appends little-endian records. In memory by default (data() holds the bytes); or streaming to a file:
// the bytes go out in windows as they are made, each window's kChecksumPiece pieces of the payload
// (the bytes from `sumFrom` on) summed on all cores and written by a thread of its own while the next
// window fills, so the whole file never sits in memory. Places written before their value is known are
// reserved with hole() and filled with patch(); finishing gives the payload's pieceChecksum64.
class ByteWriter {
 public:
  ByteWriter();
  // Streams into `fd` (an empty file, written from offset 0; `file` names it in errors).
  ByteWriter(int fd, std::string file, size_t sumFrom, unsigned threads = 0, size_t window = size_t(64) << 20);
  ~ByteWriter();
  ByteWriter(const ByteWriter&) = delete;
  ByteWriter& operator=(const ByteWriter&) = delete;

  void bytes(const void* p, size_t n) {
    if (!stream_) out_.append(static_cast<const char*>(p), n);
    else streamBytes(static_cast<const char*>(p), n);
  }
  template <class T>
  void pod(const T& v) {
    bytes(&v, sizeof v);
  }
  void u8(uint8_t v) { pod(v); }
  void u32(uint32_t v) { pod(v); }
  void f32(float v) { pod(v); }
  template <class T>
  void array(std::span<const T> v) {
    bytes(v.data(), v.size() * sizeof(T));
  }
  template <class T>
  void array(const std::vector<T>& v) {
    array(std::span<const T>(v));
  }
  template <class T>
  void array(const ViewOrVector<T>& v) {
    array(v.span());
  }
  void zeros(size_t n);
  void pad(size_t align) { zeros((align - size() % align) % align); }
  size_t size() const;
  void reserve(size_t n) { out_.reserve(n); }  // in memory: a large file grown by doubling copies itself again and again
  std::string& data() {                        // in memory: all bytes written
    if (stream_) throw std::logic_error("ByteWriter::data() of a streaming writer");
    return out_;
  }
  // n zero bytes to be patched later (streaming: the pieces holding them are summed once patched); returns
  // where they start.
  size_t hole(size_t n);
  void patch(size_t at, const void* p, size_t n);  // bytes already written: in a hole, or before sumFrom
  // Streaming: writes what is left and every patch, waits for the file; returns the payload's
  // pieceChecksum64. In memory: pieceChecksum64 of data() from sumFrom (not to be called twice).
  uint64_t finishPayload(size_t sumFrom, unsigned threads = 0);

 private:
  struct Stream;
  void streamBytes(const char* p, size_t n);
  std::string out_;
  std::unique_ptr<Stream> stream_;
};

class ByteReader {
 public:
  ByteReader(std::span<const uint8_t> data, std::string file) : d_(data), file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& what) const { failAt(pos_, what); }
  [[noreturn]] void failAt(size_t at, const std::string& what) const {
    throw fileError(file_, "byte " + std::to_string(at), what);
  }
  size_t pos() const { return pos_; }
  size_t remaining() const { return d_.size() - pos_; }
  void need(size_t n, const char* what) const {
    if (n > remaining())
      fail(std::string("file ends inside ") + what + " (needs " + std::to_string(n) + " bytes, " + std::to_string(remaining()) +
           " left)");
  }
  void raw(void* dst, size_t n, const char* what) {
    need(n, what);
    if (n) std::memcpy(dst, d_.data() + pos_, n);  // an empty vector's data() may be null: UB even for 0 bytes
    pos_ += n;
  }
  template <class T>
  T pod(const char* what) {
    T v;
    raw(&v, sizeof v, what);
    return v;
  }
  uint8_t u8(const char* what) { return pod<uint8_t>(what); }
  uint32_t u32(const char* what) { return pod<uint32_t>(what); }
  float f32(const char* what) { return pod<float>(what); }
  // A count of records of at least `minBytes` each must fit in what is left: checked before allocating.
  uint32_t count(const char* what, size_t minBytes) {
    const size_t at = pos_;
    uint32_t n = u32(what);
    if (minBytes && uint64_t(n) * minBytes > remaining())
      failAt(at,
             std::string(what) + " " + std::to_string(n) + " cannot fit in the " + std::to_string(remaining()) + " bytes left");
    return n;
  }
  // Passes over n elements of `size` bytes (to be read in place later); returns where they start.
  size_t skipArray(size_t n, size_t size, const char* what) {
    if (n > remaining() / size)
      fail(std::string("file ends inside ") + what + " (" + std::to_string(n) + " elements of " + std::to_string(size) +
           " bytes, " + std::to_string(remaining()) + " bytes left)");
    const size_t at = pos_;
    pos_ += n * size;
    return at;
  }
  template <class T>
  void array(std::vector<T>& v, size_t n, const char* what) {
    const size_t at = skipArray(n, sizeof(T), what);
    v.resize(n);
    if (n) std::memcpy(v.data(), d_.data() + at, n * sizeof(T));
  }
  template <class T>
  void array(ViewOrVector<T>& v, size_t n, const char* what) {
    array(v.writable(), n, what);
  }
  void skip(size_t n, const char* what) {
    need(n, what);
    pos_ += n;
  }
  void align(size_t a, const char* what) { skip((a - pos_ % a) % a, what); }
  std::string_view view(size_t n, const char* what) {
    need(n, what);
    std::string_view s(reinterpret_cast<const char*>(d_.data() + pos_), n);
    pos_ += n;
    return s;
  }

 private:
  std::span<const uint8_t> d_;
  std::string file_;
  size_t pos_ = 0;
};

// Whole file into memory (opened through InputFile: a regular file, at most `maxBytes`); throws
// rtr::Error naming the file.
std::vector<uint8_t> readFileBytes(const std::filesystem::path& file, uint64_t maxBytes = uint64_t(1) << 32);

// 64-bit checksum over bytes (word-wise multiply-xorshift; detects corruption, not tampering). One chain
// of dependent multiplies: it cannot be split over threads.
uint64_t checksum64(std::span<const uint8_t> data);

// The same strength on all cores: checksum64 of each 1 MiB piece, then checksum64 of those values as
// little-endian u64s. The pieces do not depend on the thread count (`threads` 0: one per core).
constexpr size_t kChecksumPiece = size_t(1) << 20;
uint64_t pieceChecksum64(std::span<const uint8_t> data, unsigned threads = 0);

}  // namespace rtr
