#include "scene/binio.hpp"

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

}  // namespace rtr
