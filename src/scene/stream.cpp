#include "scene/stream.hpp"

#include <cstring>
#include <vector>

#include <zstd.h>

#include "core/error.hpp"
#include "core/input_file.hpp"

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

class ZstdSource final : public ByteSource {
 public:
  ZstdSource(std::unique_ptr<RawSource> raw, std::string name)
      : raw_(std::move(raw)), name_(std::move(name)), in_(ZSTD_DStreamInSize()), z_(ZSTD_createDStream()) {
    if (!z_) throw fileError(name_, "", "out of memory creating the zstd decoder");
    ZSTD_initDStream(z_.get());
  }
  size_t read(char* dst, size_t n) override {
    ZSTD_outBuffer out{dst, n, 0};
    while (out.pos == 0 && n > 0) {
      // Only ask for more input once the decoder has nothing left to flush from the previous input.
      if (inBuf_.pos == inBuf_.size && !mayHoldOutput_) {
        size_t k = eof_ ? 0 : raw_->read(in_.data(), in_.size());
        if (k == 0) {
          eof_ = true;
          // A stream ends cleanly only on a frame boundary with all output flushed.
          if (lastHint_ != 0)
            throw fileError(name_, "byte " + std::to_string(consumed_),
                            "truncated zstd stream (the compressed data ends inside a frame)");
          if (!sawData_) throw fileError(name_, "byte 0", "empty file is not a zstd stream");
          break;
        }
        sawData_ = true;
        inBuf_ = {in_.data(), k, 0};
      }
      size_t before = inBuf_.pos;
      size_t hint = ZSTD_decompressStream(z_.get(), &out, &inBuf_);
      consumed_ += inBuf_.pos - before;
      if (ZSTD_isError(hint))
        throw fileError(name_, "byte " + std::to_string(consumed_),
                        std::string("corrupt zstd stream: ") + ZSTD_getErrorName(hint));
      lastHint_ = hint;
      mayHoldOutput_ = out.pos == out.size;
    }
    return out.pos;
  }
  uint64_t consumed() const override { return consumed_; }
  uint64_t fileSize() const override { return raw_->size(); }

 private:
  std::unique_ptr<RawSource> raw_;
  std::string name_;
  std::vector<char> in_;
  ZSTD_inBuffer inBuf_{nullptr, 0, 0};
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

std::unique_ptr<ByteSource> openSource(const std::filesystem::path& file) {
  auto raw = std::make_unique<RawFile>(file);
  if (isZstdName(file)) return std::make_unique<ZstdSource>(std::move(raw), file.string());
  return std::make_unique<PlainSource>(std::move(raw));
}

std::unique_ptr<ByteSource> memorySource(std::string data, std::string name, bool zstd) {
  auto raw = std::make_unique<RawMemory>(std::move(data));
  if (zstd) return std::make_unique<ZstdSource>(std::move(raw), std::move(name));
  return std::make_unique<PlainSource>(std::move(raw));
}

}  // namespace rtr
