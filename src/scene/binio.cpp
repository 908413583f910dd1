#include "scene/binio.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <map>
#include <stdexcept>
#include <thread>

#include "core/parallel.hpp"

namespace rtr {

std::vector<uint8_t> readFileBytes(const std::filesystem::path& file, uint64_t maxBytes) {
  InputFile in(file);
  if (in.size() > maxBytes)
    throw fileError(in.name(), "", std::to_string(in.size()) + " bytes; the limit is " + std::to_string(maxBytes));
  std::vector<uint8_t> out(in.size());
  out.resize(in.read(out.data(), out.size()));
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

// The streaming writer's state: two window buffers (one filling while the other is written), the sums of
// the payload's pieces so far, and the pieces that hold a hole (kept until it is patched).
struct ByteWriter::Stream {
  int fd;
  std::string file;
  size_t sumFrom, window;
  unsigned threads;
  std::unique_ptr<char[]> buf[2];
  int cur = 0;
  size_t base = 0, used = 0;  // buf[cur] holds the file's bytes [base, base + used)
  size_t limit;               // where this window ends: sumFrom + k · window
  std::thread writer;         // writing the other buffer
  int writeError = 0;
  bool finished = false;
  std::vector<uint64_t> sums;
  std::map<size_t, std::string> deferred;               // piece -> its bytes, summed at the end
  std::vector<std::pair<size_t, std::string>> patches;  // bytes already handed to the writer: put at the end

  void wait() {
    if (writer.joinable()) writer.join();
    if (writeError) throw fileError(file, "", std::string("cannot write: ") + std::strerror(writeError));
  }
  void writeAt(const char* p, size_t n, size_t at, int& err) const {
    while (n > 0 && !err) {
      const ssize_t k = ::pwrite(fd, p, n, off_t(at));
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0) err = k < 0 ? errno : EIO;
      else p += k, n -= size_t(k), at += size_t(k);
    }
  }
  // Sums the window's pieces (the last, partial one too when `last`) and hands it to the writer thread.
  void flush(bool last) {
    char* b = buf[cur].get();
    const size_t end = base + used, from = std::max(base, sumFrom);
    const size_t first = (from - sumFrom) / kChecksumPiece;
    const size_t stop = end <= sumFrom ? first
                        : last         ? (end - sumFrom + kChecksumPiece - 1) / kChecksumPiece
                                       : (end - sumFrom) / kChecksumPiece;
    sums.resize(std::max(sums.size(), stop));
    parallelFor(stop - first, threads, [&](size_t j) {
      const size_t i = first + j, at = sumFrom + i * kChecksumPiece, n = std::min(kChecksumPiece, end - at);
      const char* p = b + (at - base);
      if (const auto d = deferred.find(i); d != deferred.end()) d->second.assign(p, n);
      else sums[i] = checksum64({reinterpret_cast<const uint8_t*>(p), n});
    });
    wait();
    writer = std::thread([this, b, n = used, at = base] {
      writeAt(b, n, at, writeError);
      // Starts the disk's writeback now, so that the closing fsync waits only for the last windows.
      if (!writeError) ::sync_file_range(fd, off_t(at), off_t(n), SYNC_FILE_RANGE_WRITE);
    });
    cur ^= 1;
    base = end;
    used = 0;
    limit += window;
  }
  // n bytes of p, or zeros when p is null; large copies on all cores.
  void put(const char* p, size_t n) {
    while (n > 0) {
      if (!buf[cur]) buf[cur].reset(new char[sumFrom + window]);
      const size_t k = std::min(n, limit - (base + used));
      char* dst = buf[cur].get() + used;
      constexpr size_t kCopyPiece = size_t(1) << 20;
      if (!p) std::memset(dst, 0, k);
      else if (k < 4 * kCopyPiece) std::memcpy(dst, p, k);
      else
        parallelFor((k + kCopyPiece - 1) / kCopyPiece, threads, [&](size_t j) {
          std::memcpy(dst + j * kCopyPiece, p + j * kCopyPiece, std::min(kCopyPiece, k - j * kCopyPiece));
        });
      used += k;
      n -= k;
      if (p) p += k;
      if (base + used == limit) flush(false);
    }
  }
};

ByteWriter::ByteWriter() = default;

ByteWriter::ByteWriter(int fd, std::string file, size_t sumFrom, unsigned threads, size_t window)
    : stream_(new Stream{fd, std::move(file), sumFrom, window, threads}) {
  if (window == 0 || window % kChecksumPiece != 0) throw std::logic_error("ByteWriter: window not a multiple of the piece");
  stream_->limit = sumFrom + window;
}

ByteWriter::~ByteWriter() {
  if (stream_ && stream_->writer.joinable()) stream_->writer.join();
}

void ByteWriter::streamBytes(const char* p, size_t n) { stream_->put(p, n); }

void ByteWriter::zeros(size_t n) {
  if (!stream_) out_.append(n, '\0');
  else stream_->put(nullptr, n);
}

size_t ByteWriter::size() const { return stream_ ? stream_->base + stream_->used : out_.size(); }

size_t ByteWriter::hole(size_t n) {
  const size_t at = size();
  if (Stream* s = stream_.get())
    for (size_t b = std::max(at, s->sumFrom); b < at + n;
         b = s->sumFrom + ((b - s->sumFrom) / kChecksumPiece + 1) * kChecksumPiece)
      s->deferred.emplace((b - s->sumFrom) / kChecksumPiece, std::string());
  zeros(n);
  return at;
}

void ByteWriter::patch(size_t at, const void* data, size_t n) {
  const char* p = static_cast<const char*>(data);
  if (at + n > size()) throw std::logic_error("ByteWriter::patch past the end");
  Stream* s = stream_.get();
  if (!s) return void(std::memcpy(out_.data() + at, p, n));
  if (s->finished) {
    int err = 0;
    s->writeAt(p, n, at, err);
    if (err) throw fileError(s->file, "", std::string("cannot write: ") + std::strerror(err));
    return;
  }
  const size_t before = at < s->base ? std::min(n, s->base - at) : 0;  // already handed on
  if (before) {
    for (size_t b = std::max(at, s->sumFrom); b < at + before;
         b = s->sumFrom + ((b - s->sumFrom) / kChecksumPiece + 1) * kChecksumPiece)
      if (!s->deferred.count((b - s->sumFrom) / kChecksumPiece)) throw std::logic_error("ByteWriter::patch outside a hole");
    s->patches.emplace_back(at, std::string(p, before));
  }
  if (n > before) std::memcpy(s->buf[s->cur].get() + (at + before - s->base), p + before, n - before);
}

uint64_t ByteWriter::finishPayload(size_t sumFrom, unsigned threads) {
  Stream* s = stream_.get();
  if (!s) {
    const auto* b = reinterpret_cast<const uint8_t*>(out_.data());
    return pieceChecksum64({b + sumFrom, out_.size() - sumFrom}, threads);
  }
  if (sumFrom != s->sumFrom || s->finished) throw std::logic_error("ByteWriter::finishPayload");
  s->flush(true);
  s->wait();
  for (const auto& [at, bytes] : s->patches)  // into the kept pieces, then summed
    for (auto& [i, piece] : s->deferred) {
      const size_t p0 = s->sumFrom + i * kChecksumPiece, lo = std::max(at, p0),
                   hi = std::min(at + bytes.size(), p0 + piece.size());
      if (lo < hi) std::memcpy(piece.data() + (lo - p0), bytes.data() + (lo - at), hi - lo);
    }
  for (const auto& [i, piece] : s->deferred)
    s->sums[i] = checksum64({reinterpret_cast<const uint8_t*>(piece.data()), piece.size()});
  s->finished = true;
  for (const auto& [at, bytes] : s->patches) patch(at, bytes.data(), bytes.size());
  s->buf[0].reset();
  s->buf[1].reset();
  return checksum64({reinterpret_cast<const uint8_t*>(s->sums.data()), s->sums.size() * 8});
}

}  // namespace rtr
