#include "scene/stream.hpp"

#include <cstring>
#include <vector>

#include <zstd.h>

#include "core/error.hpp"
#include "core/input_file.hpp"
#include "core/parallel.hpp"

namespace rtr {
namespace {

// Raw bytes from a file or memory, the layer under the optional zstd decoder.
class RawSource {
 public:
  virtual ~RawSource() = default;
  virtual size_t read(char* dst, size_t n) = 0;
  virtual uint64_t size() const = 0;
};

class RawFile final : public RawSource {
 public:
  explicit RawFile(const std::filesystem::path& file) : in_(file, "scene file") {}
  size_t read(char* dst, size_t n) override { return in_.read(dst, n); }
  uint64_t size() const override { return in_.size(); }

 private:
  InputFile in_;  // a regular file only, read no further than its size at open
};

class RawMemory final : public RawSource {
 public:
  explicit RawMemory(std::string data) : data_(std::move(data)) {}
  size_t read(char* dst, size_t n) override {
    size_t k = std::min(n, data_.size() - pos_);
    std::memcpy(dst, data_.data() + pos_, k);
    pos_ += k;
    return k;
  }
  uint64_t size() const override { return data_.size(); }

 private:
  std::string data_;
  size_t pos_ = 0;
};

class PlainSource final : public ByteSource {
 public:
  explicit PlainSource(std::unique_ptr<RawSource> raw) : raw_(std::move(raw)) {}
  size_t read(char* dst, size_t n) override {
    size_t k = raw_->read(dst, n);
    consumed_ += k;
    return k;
  }
  uint64_t consumed() const override { return consumed_; }
  uint64_t fileSize() const override { return raw_->size(); }

 private:
  std::unique_ptr<RawSource> raw_;
  uint64_t consumed_ = 0;
};

struct DStreamFree {
  void operator()(ZSTD_DStream* z) const { ZSTD_freeDStream(z); }
};

// A zstd stream decoded as it is read. Where the file is a series of frames that each say their size (our
// scenegen writes one per few MiB of text; pzstd does too), the frames that fit the caller's buffer are
// decoded at once on all cores; anything else (one frame of a whole file, sizes not given, damage) is
// streamed on one thread, which also names the byte where a stream is cut or corrupt.
class ZstdSource final : public ByteSource {
 public:
  ZstdSource(std::unique_ptr<RawSource> raw, std::string name, unsigned threads)
      : raw_(std::move(raw)), name_(std::move(name)), threads_(threads), buf_(ZSTD_DStreamInSize()), z_(ZSTD_createDStream()) {
    if (!z_) throw fileError(name_, "", "out of memory creating the zstd decoder");
    ZSTD_initDStream(z_.get());
  }
  size_t read(char* dst, size_t n) override {
    if (n == 0) return 0;
    for (;;) {
      if (spilled_ < spill_.size()) {  // the rest of a frame larger than the caller's buffer
        const size_t k = std::min(n, spill_.size() - spilled_);
        std::memcpy(dst, spill_.data() + spilled_, k);
        spilled_ += k;
        return k;
      }
      if (lastHint_ != 0) break;  // inside a streamed frame
      const uint64_t before = consumed_;
      if (const size_t k = readFrames(dst, n)) return k;
      if (consumed_ == before) break;  // not a frame to decode whole: stream it
    }
    return readStream(dst, n);
  }
  uint64_t consumed() const override { return consumed_; }
  uint64_t fileSize() const override { return raw_->size(); }

 private:
  static constexpr size_t kMaxFrame = size_t(32) << 20;  // larger frames are streamed
  static constexpr size_t kHeaderMax = 18;               // a frame header's largest size (zstd format)

  // At least `want` compressed bytes from pos_ on, unless the file ends first; false then.
  bool more(size_t want) {
    if (end_ - pos_ >= want) return true;
    std::memmove(buf_.data(), buf_.data() + pos_, end_ - pos_);
    end_ -= pos_;
    pos_ = 0;
    if (buf_.size() < want) buf_.resize(want);
    while (end_ < want && !eof_) {
      const size_t k = raw_->read(buf_.data() + end_, buf_.size() - end_);
      eof_ = k == 0;
      end_ += k;
    }
    return end_ >= want;
  }

  // Whole frames of known size that fit in n (or the first one, into spill_), decoded on all cores;
  // 0 when the next frame is not one of those.
  size_t readFrames(char* dst, size_t n) {
    struct Frame {
      size_t in, packed, out, size;  // offset from pos_, compressed size, offset in the output, decoded size
    };
    std::vector<Frame> frames;
    size_t rel = 0, total = 0;
    for (;;) {
      more(rel + kHeaderMax);
      const size_t avail = end_ - pos_ - rel;
      if (avail == 0) break;
      const unsigned long long size = ZSTD_getFrameContentSize(buf_.data() + pos_ + rel, avail);
      if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN || size > kMaxFrame) break;
      if (!frames.empty() && total + size > n) break;
      more(rel + ZSTD_compressBound(size) + kHeaderMax + 4);
      const size_t stored = ZSTD_findFrameCompressedSize(buf_.data() + pos_ + rel, end_ - pos_ - rel);
      if (ZSTD_isError(stored)) break;  // cut short or damaged: the stream names the byte
      frames.push_back({rel, stored, total, size_t(size)});
      rel += stored;
      total += size;
      if (total >= n) break;
    }
    if (frames.empty()) return 0;
    const bool spill = total > n;  // one frame, larger than the caller's buffer
    if (spill) spill_.resize(total), spilled_ = 0;
    char* out = spill ? spill_.data() : dst;
    parallelFor(frames.size(), threads_, [&](size_t i) {
      const Frame& f = frames[i];
      const size_t got = ZSTD_decompress(out + f.out, f.size, buf_.data() + pos_ + f.in, f.packed);
      if (ZSTD_isError(got) || got != f.size)
        throw fileError(
            name_, "byte " + std::to_string(consumed_ + f.in),
            std::string("corrupt zstd stream: ") + (ZSTD_isError(got) ? ZSTD_getErrorName(got) : "frame size differs"));
    });
    pos_ += rel;
    consumed_ += rel;
    sawData_ = true;
    if (!spill) return total;
    spilled_ = std::min(n, total);
    std::memcpy(dst, spill_.data(), spilled_);
    return spilled_;
  }

  size_t readStream(char* dst, size_t n) {
    ZSTD_outBuffer out{dst, n, 0};
    while (out.pos == 0 && n > 0) {
      // Only ask for more input once the decoder has nothing left to flush from the previous input.
      if (pos_ == end_ && !mayHoldOutput_) {
        pos_ = end_ = 0;
        if (!more(1)) {
          // A stream ends cleanly only on a frame boundary with all output flushed.
          if (lastHint_ != 0)
            throw fileError(name_, "byte " + std::to_string(consumed_),
                            "truncated zstd stream (the compressed data ends inside a frame)");
          if (!sawData_) throw fileError(name_, "byte 0", "empty file is not a zstd stream");
          break;
        }
        sawData_ = true;
      }
      ZSTD_inBuffer in{buf_.data() + pos_, end_ - pos_, 0};
      const size_t hint = ZSTD_decompressStream(z_.get(), &out, &in);
      pos_ += in.pos;
      consumed_ += in.pos;
      if (ZSTD_isError(hint))
        throw fileError(name_, "byte " + std::to_string(consumed_),
                        std::string("corrupt zstd stream: ") + ZSTD_getErrorName(hint));
      lastHint_ = hint;
      mayHoldOutput_ = out.pos == out.size;
    }
    return out.pos;
  }

  std::unique_ptr<RawSource> raw_;
  std::string name_;
  unsigned threads_;
  std::vector<char> buf_, spill_;  // compressed bytes [pos_, end_); a decoded frame's rest from spilled_
  size_t pos_ = 0, end_ = 0, spilled_ = 0;
  std::unique_ptr<ZSTD_DStream, DStreamFree> z_;
  uint64_t consumed_ = 0;
  size_t lastHint_ = 0;
  bool eof_ = false, sawData_ = false, mayHoldOutput_ = false;
};

}  // namespace

bool isZstdName(const std::filesystem::path& file) {
  const std::string n = file.filename().string();
  auto ends = [&](std::string_view s) { return n.size() >= s.size() && n.compare(n.size() - s.size(), s.size(), s) == 0; };
  return ends(".zst") || ends(".obj-zstd") || ends(".zstd");
}

std::unique_ptr<ByteSource> openSource(const std::filesystem::path& file, unsigned threads) {
  auto raw = std::make_unique<RawFile>(file);
  if (isZstdName(file)) return std::make_unique<ZstdSource>(std::move(raw), file.string(), threads);
  return std::make_unique<PlainSource>(std::move(raw));
}

std::unique_ptr<ByteSource> memorySource(std::string data, std::string name, bool zstd, unsigned threads) {
  auto raw = std::make_unique<RawMemory>(std::move(data));
  if (zstd) return std::make_unique<ZstdSource>(std::move(raw), std::move(name), threads);
  return std::make_unique<PlainSource>(std::move(raw));
}

}  // namespace rtr
