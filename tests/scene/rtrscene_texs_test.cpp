// .rtrscene version 6: the TEXS chunk (textures baked as the GPU samples them) round-trips byte for byte,
// from memory and from a mapped file, and every fault of its framing, table or pieces is refused with the
// file and the byte offset; version 5 and older write no chunks.
#include <cstring>
#include <random>

#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "core/mip_reference.hpp"
#include "scene/baked_texels.hpp"
#include "scene/binio.hpp"
#include "scene/rtrscene.hpp"
#include "scene/textures.hpp"
#include "test_paths.hpp"

using namespace rtr;
using ::testing::HasSubstr;

namespace {

std::span<const uint8_t> span(const std::string& b) { return {reinterpret_cast<const uint8_t*>(b.data()), b.size()}; }

// A chain of the right size: smooth (zstd shrinks it) or noise (stored as it is).
std::vector<uint8_t> chainBytes(BakedFormat f, uint32_t w, uint32_t h, bool noise) {  // any format: bytes
  BakedTexels layout;
  layout.format = f;
  layout.width = w;
  layout.height = h;
  std::vector<uint8_t> c(layout.bytes());
  std::mt19937 rng(7);
  for (size_t i = 0; i < c.size(); ++i) c[i] = noise ? uint8_t(rng()) : uint8_t((i / 64) % 251);
  return c;
}

// Three textures: a large smooth sRGB one (several zstd pieces), an odd-sized R8 one, a noisy one (stored raw).
Scene bakedScene() {
  Scene s;
  Texture a{"tex/a.png", true, 4}, b{"tex/b.png", false, 1}, c{"tex/c.png", false, 4};
  b.sourceChannel = 2;
  a.baked = packBakedTexels(BakedFormat::Rgba8, 512, 300, chainBytes(BakedFormat::Rgba8, 512, 300, false));
  b.baked = packBakedTexels(BakedFormat::R8, 37, 5, chainBytes(BakedFormat::R8, 37, 5, false));
  c.baked = packBakedTexels(BakedFormat::Rgba8, 64, 64, chainBytes(BakedFormat::Rgba8, 64, 64, true));
  s.textures = {a, b, c};
  Material m;
  m.name = "m";
  m.textures[0] = 0;
  m.textures[1] = 1;
  m.textures[2] = 2;
  s.materials = {m};
  Mesh q;
  q.name = "q";
  q.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}};
  q.texcoords = {{0, 0}, {1, 0}, {1, 1}};
  q.indices = {0, 1, 2};
  q.bounds = {{0, 0, 0}, {1, 1, 0}};
  s.meshes = {q};
  return s;
}

std::vector<uint8_t> unpackAll(const BakedTexels& t) {
  std::vector<uint8_t> chain(t.bytes());
  for (size_t k = 0; k < t.pieces.size(); ++k) unpackBakedPiece(t, k, chain.data());
  return chain;
}

void reseal(std::string& b) {
  const uint64_t payload = b.size() - 80;
  std::memcpy(b.data() + 32, &payload, 8);
  const uint64_t sum = pieceChecksum64(span(b).subspan(80));
  std::memcpy(b.data() + 40, &sum, 8);
}

std::string decodeError(const std::string& bytes) {
  try {
    const Scene s = decodeRtrScene(span(bytes), "t.rtrscene", 1);
    for (const Texture& t : s.textures) unpackAll(*t.baked);  // the pieces' own faults show on unpacking
  } catch (const Error& e) { return e.what(); }
  return "(no error)";
}

}  // namespace

TEST(RtrSceneTexs, BakedTexelsRoundTripFromMemoryAndFromAMappedFile) {
  const Scene want = bakedScene();
  EXPECT_EQ(want.textures[0].baked->pieces.size(), 4u) << "512x300 RGBA with its mips (819 KiB): four pieces of 256 KiB";
  EXPECT_LT(want.textures[0].baked->pieces[0].stored, kBakedPiece) << "smooth texels are compressed";
  EXPECT_EQ(want.textures[2].baked->pieces[0].stored, want.textures[2].baked->pieceBytes(0)) << "noise is stored as it is";
  const std::string bytes = encodeRtrScene(want);
  ASSERT_EQ(bytes[8], 6);
  const auto file = std::filesystem::temp_directory_path() / ("rtr-texs-" + std::to_string(::getpid()) + ".rtrscene");
  writeFileAtomic(file, bytes);
  for (int from = 0; from < 2; ++from) {
    const Scene got = from == 0 ? decodeRtrScene(span(bytes), "t.rtrscene", 1) : loadRtrScene(file);
    ASSERT_EQ(got.textures.size(), 3u);
    for (size_t i = 0; i < 3; ++i) {
      const BakedTexels &a = *want.textures[i].baked, &b = *got.textures[i].baked;
      EXPECT_EQ(b.format, a.format);
      EXPECT_EQ(b.width, a.width);
      EXPECT_EQ(b.height, a.height);
      EXPECT_EQ(unpackAll(b), unpackAll(a)) << "texture " << i;
      EXPECT_EQ(got.textures[i].path, want.textures[i].path);
    }
    // Level 0 is what the CPU tracer reads.
    const TexelData l0 = decodeTexture(got, got.textures[1]);
    EXPECT_EQ(l0.width, 37u);
    EXPECT_EQ(l0.channels, 1u);
    const std::vector<uint8_t> c = chainBytes(BakedFormat::R8, 37, 5, false);
    EXPECT_EQ(l0.texels, std::vector<uint8_t>(c.begin(), c.begin() + 37 * 5));
    EXPECT_EQ(encodeRtrScene(got), bytes) << "re-encoding copies the stored pieces";
  }
  std::filesystem::remove(file);
  EXPECT_THAT([&] { encodeRtrScene(want, 5); }, testing::ThrowsMessage<Error>(HasSubstr("with baked textures")));
  Scene mixed = want;
  mixed.textures[1].baked = nullptr;
  EXPECT_THAT([&] { encodeRtrScene(mixed); }, testing::ThrowsMessage<Error>(HasSubstr("all baked or none")));
}

TEST(RtrSceneTexs, DamagedChunksAreRefusedWithTheByteOffset) {
  const std::string good = encodeRtrScene(bakedScene());
  const size_t chunk = good.find("TEXS");
  ASSERT_NE(chunk, std::string::npos);
  ASSERT_EQ(chunk % 16, 0u);
  const size_t body = chunk + 16;
  EXPECT_EQ(decodeError(good), "(no error)");

  // Truncated: the chunk's declared size runs past the file (payload size and checksum made to match).
  std::string cut = good.substr(0, good.size() - 4096);
  reseal(cut);
  EXPECT_THAT(decodeError(cut), HasSubstr("t.rtrscene: byte " + std::to_string(chunk + 8) + ": chunk 'TEXS' of "));
  // Cut right after the header: the header itself is incomplete.
  std::string header = good.substr(0, chunk + 10);
  reseal(header);
  EXPECT_THAT(decodeError(header), HasSubstr("file ends inside a chunk header"));
  // An unknown tag, and a second TEXS chunk.
  std::string unknown = good;
  std::memcpy(unknown.data() + chunk, "TEXZ", 4);
  reseal(unknown);
  EXPECT_THAT(decodeError(unknown), HasSubstr("byte " + std::to_string(chunk) + ": unknown chunk 'TEXZ'"));
  std::string twice = good + good.substr(chunk);
  reseal(twice);
  EXPECT_THAT(decodeError(twice), HasSubstr("byte " + std::to_string(good.size()) + ": chunk 'TEXS' repeated"));
  // A texel format that does not fit the texture's channels (texture 1 is R8).
  std::string format = good;
  const uint32_t rgba = 1;
  std::memcpy(format.data() + body + 16 + 32, &rgba, 4);
  reseal(format);
  EXPECT_THAT(decodeError(format), HasSubstr("byte " + std::to_string(body + 48) + ": baked texture 1: texel format 1"));
  // A piece stored elsewhere than right after the one before.
  std::string offset = good;
  const size_t table = body + 16 + 3 * 32;
  offset[table + 16] ^= 1;  // piece 1's offset
  reseal(offset);
  EXPECT_THAT(decodeError(offset), HasSubstr("byte " + std::to_string(table + 16) + ": baked texture 0 piece 1: stored at"));
  // A damaged zstd frame: its layout passes, unpacking names the piece's first byte.
  std::string frame = good;
  uint64_t firstPiece;
  std::memcpy(&firstPiece, good.data() + table, 8);
  frame[body + firstPiece + 40] ^= 0x5A;
  reseal(frame);
  EXPECT_THAT(decodeError(frame),
              HasSubstr("t.rtrscene: byte " + std::to_string(body + firstPiece) + ": baked texture piece 0 does not unpack"));
}

// BC4 as Vulkan's data format specification decodes it (values written out here from its formulas), and
// the encoder within its bound on smooth texels; BC1/BC3/BC4 chains round-trip through the file.
TEST(RtrSceneTexs, BlockCompressedLevelsDecodeAsSpecifiedAndRoundTrip) {
  // red_0 200 > red_1 100: eight values 200, 100, then (6·200+100)/7 … (200+6·100)/7.
  uint8_t block[8] = {200, 100};
  const int want8[8] = {200, 100, 186, 171, 157, 143, 129, 114};
  uint64_t bits = 0;
  for (int i = 0; i < 16; ++i) bits |= uint64_t(i % 8) << (3 * i);
  for (int b = 0; b < 6; ++b) block[2 + b] = uint8_t(bits >> (8 * b));
  std::vector<uint8_t> t = decodeBakedLevel(BakedFormat::Bc4, 4, 4, block);
  for (int i = 0; i < 16; ++i) EXPECT_EQ(t[i], want8[i % 8]) << "texel " << i;
  // red_0 50 <= red_1 150: six values 50, 150, (4·50+150)/5 … (50+4·150)/5, then 0 and 255.
  block[0] = 50;
  block[1] = 150;
  const int want6[8] = {50, 150, 70, 90, 110, 130, 0, 255};
  t = decodeBakedLevel(BakedFormat::Bc4, 3, 2, block);  // a partial block: the texels inside the level
  ASSERT_EQ(t.size(), 6u);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) EXPECT_EQ(t[y * 3 + x], want6[(y * 4 + x) % 8]);
  // Smooth texels: within (max − min) / 14 of the block, plus rounding.
  std::vector<uint8_t> smooth(21 * 10);
  for (size_t i = 0; i < smooth.size(); ++i) smooth[i] = uint8_t(40 + (i % 21) * 5 + (i / 21) * 3);
  const std::vector<uint8_t> back =
      decodeBakedLevel(BakedFormat::Bc4, 21, 10, encodeBakedLevel(BakedFormat::Bc4, 21, 10, smooth.data()).data());
  for (size_t i = 0; i < smooth.size(); ++i) EXPECT_LE(std::abs(int(back[i]) - int(smooth[i])), 2) << i;

  Scene s = bakedScene();
  const uint32_t w = 19, h = 11;
  for (auto [i, f] : {std::pair{0, BakedFormat::Bc3}, std::pair{1, BakedFormat::Bc4}, std::pair{2, BakedFormat::Bc1}}) {
    BakedTexels layout;
    layout.format = f;
    layout.width = w;
    layout.height = h;
    EXPECT_EQ(layout.levelOffsets()[1], ((w + 3) / 4) * ((h + 3) / 4) * (f == BakedFormat::Bc3 ? 16u : 8u) + 15 & ~15u);
    s.textures[i].baked = packBakedTexels(f, w, h, chainBytes(f, w, h, i == 2));
  }
  const std::string bytes = encodeRtrScene(s);
  const Scene got = decodeRtrScene(span(bytes), "bc.rtrscene", 1);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(got.textures[i].baked->format, s.textures[i].baked->format);
    EXPECT_EQ(unpackAll(*got.textures[i].baked), unpackAll(*s.textures[i].baked));
  }
  const TexelData l0 = decodeTexture(got, got.textures[1]);  // the tracer's level 0: BC4 decoded
  EXPECT_EQ(l0.channels, 1u);
  EXPECT_EQ(l0.texels.size(), size_t(w) * h);
  // A BC4 chain given to a four-channel texture is refused where it is named.
  std::string wrong = bytes;
  const size_t body = wrong.find("TEXS") + 16;
  const uint32_t bc4 = uint32_t(BakedFormat::Bc4);
  std::memcpy(wrong.data() + body + 16, &bc4, 4);
  reseal(wrong);
  EXPECT_THAT(decodeError(wrong), HasSubstr("byte " + std::to_string(body + 16) + ": baked texture 0: texel format 5"));
}
