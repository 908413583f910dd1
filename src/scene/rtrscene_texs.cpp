#include "scene/rtrscene_texs.hpp"

#include "core/mip_reference.hpp"
#include "scene/baked_texels.hpp"
#include "scene/textures.hpp"

namespace rtr {
namespace {

constexpr size_t kTexsHeader = 16, kTexsRecord = 32, kTexsPiece = 16;
constexpr uint32_t kMaxSide = 32768;  // as the image decoders (core/image.cpp)

// A baked format fits a texture whose slot decodes to its channel count.
bool fits(BakedFormat f, const Texture& t) { return int(bakedChannels(f)) == decodeChannels(t); }

}  // namespace

bool hasBakedTextures(const Scene& scene) {
  for (const Texture& t : scene.textures)
    if (t.baked) return true;
  return false;
}

void writeTexs(ByteWriter& w, const Scene& scene) {
  w.u32(uint32_t(scene.textures.size()));
  w.u32(uint32_t(kBakedPiece));
  w.pod(uint64_t(0));
  for (const Texture& t : scene.textures) {
    if (!t.baked) throw Error("texture '" + t.path.string() + "' is not baked: a file's textures are all baked or none");
    const BakedTexels& b = *t.baked;
    if (!fits(b.format, t)) throw Error("texture '" + t.path.string() + "': baked format does not match its channels");
    w.u32(uint32_t(b.format));
    w.u32(b.width);
    w.u32(b.height);
    w.u32(b.levels());
    w.pod(b.bytes());
    w.u32(uint32_t(b.pieces.size()));
    w.u32(0);
  }
  // Pieces are stored in order, back to back, after the table: offsets from the body's start.
  size_t pieces = 0;
  for (const Texture& t : scene.textures) pieces += t.baked->pieces.size();
  uint64_t at = (kTexsHeader + kTexsRecord * scene.textures.size() + kTexsPiece * pieces + 15) & ~uint64_t(15);
  for (const Texture& t : scene.textures)
    for (const BakedPiece& p : t.baked->pieces) {
      w.pod(at);
      w.u32(p.stored);
      w.u32(0);
      at += p.stored;
    }
  w.pad(16);
  for (const Texture& t : scene.textures)
    for (const BakedPiece& p : t.baked->pieces) w.bytes(t.baked->data.data() + p.at, p.stored);
}

void readTexs(ByteReader& r, size_t end, std::span<const uint8_t> bytes, Scene& scene, const std::shared_ptr<const void>& owner,
              const std::string& file) {
  const size_t body = r.pos();
  const size_t size = end - body;
  auto need = [&](uint64_t n, const char* what) {
    if (n > end - r.pos())
      r.fail(std::string("TEXS chunk ends inside ") + what + " (needs " + std::to_string(n) + " bytes, " +
             std::to_string(end - r.pos()) + " left)");
  };
  need(kTexsHeader, "its header");
  const uint32_t count = r.u32("the TEXS header");
  if (count != scene.textures.size())
    r.failAt(body, "TEXS holds " + std::to_string(count) + " textures; the file has " + std::to_string(scene.textures.size()));
  if (r.u32("the TEXS header") != kBakedPiece) r.failAt(body + 4, "TEXS piece size is not " + std::to_string(kBakedPiece));
  if (r.pod<uint64_t>("the TEXS header") != 0) r.failAt(body + 8, "reserved TEXS field is not 0");
  need(uint64_t(count) * kTexsRecord, "its texture records");
  std::vector<std::shared_ptr<BakedTexels>> baked(count);
  uint64_t pieces = 0;
  for (uint32_t i = 0; i < count; ++i) {
    const size_t at = r.pos();
    auto b = std::make_shared<BakedTexels>();
    const std::string which = "baked texture " + std::to_string(i);
    const uint32_t format = r.u32("a TEXS record");
    b->width = r.u32("a TEXS record");
    b->height = r.u32("a TEXS record");
    const uint32_t levels = r.u32("a TEXS record");
    const uint64_t chain = r.pod<uint64_t>("a TEXS record");
    const uint32_t n = r.u32("a TEXS record");
    if (r.u32("a TEXS record") != 0) r.failAt(at + 28, which + ": reserved field is not 0");
    const Texture& t = scene.textures[i];
    if (!bakedKnown(format)) r.failAt(at, which + ": unknown texel format " + std::to_string(format));
    b->format = BakedFormat(format);
    if (!fits(b->format, t))
      r.failAt(at, which + ": texel format " + std::to_string(format) + " does not match the texture's " +
                       std::to_string(t.channels) + " channels");
    if (b->width < 1 || b->width > kMaxSide || b->height < 1 || b->height > kMaxSide)
      r.failAt(at + 4, which + ": size " + std::to_string(b->width) + "x" + std::to_string(b->height) + " not in 1..32768");
    if (levels != b->levels())
      r.failAt(at + 12, which + ": " + std::to_string(levels) + " levels, not the full chain's " + std::to_string(b->levels()));
    if (chain != b->bytes())
      r.failAt(at + 16, which + ": " + std::to_string(chain) + " texel bytes, not the chain's " + std::to_string(b->bytes()));
    if (n != (chain + kBakedPiece - 1) / kBakedPiece)
      r.failAt(at + 24, which + ": " + std::to_string(n) + " pieces for " + std::to_string(chain) + " bytes");
    pieces += n;
    baked[i] = std::move(b);
  }
  need(pieces * kTexsPiece, "its piece table");
  // Stored bytes start after the table (pad16) and follow one another without gaps: each piece is checked
  // against the one before, its size against its texels and the chunk's end.
  uint64_t next = (kTexsHeader + kTexsRecord * uint64_t(count) + kTexsPiece * pieces + 15) & ~uint64_t(15);
  for (uint32_t i = 0; i < count; ++i) {
    BakedTexels& b = *baked[i];
    const uint64_t n = (b.bytes() + kBakedPiece - 1) / kBakedPiece;
    b.pieces.resize(n);
    for (uint64_t k = 0; k < n; ++k) {
      const size_t at = r.pos();
      const uint64_t offset = r.pod<uint64_t>("the TEXS piece table");
      const uint32_t stored = r.u32("the TEXS piece table");
      if (r.u32("the TEXS piece table") != 0) r.failAt(at + 12, "TEXS piece: reserved field is not 0");
      const std::string which = "baked texture " + std::to_string(i) + " piece " + std::to_string(k);
      if (offset != next) r.failAt(at, which + ": stored at " + std::to_string(offset) + ", not at " + std::to_string(next));
      if (stored < 1 || stored > b.pieceBytes(k))
        r.failAt(at + 8,
                 which + ": " + std::to_string(stored) + " stored bytes for " + std::to_string(b.pieceBytes(k)) + " texel bytes");
      if (offset + stored > size)
        r.failAt(at + 8, which + ": ends at byte " + std::to_string(body + offset + stored) + ", past the TEXS chunk's end " +
                             std::to_string(end));
      b.pieces[k] = {offset, stored};
      next = offset + stored;
    }
  }
  r.align(16, "the TEXS piece table");
  if (r.pos() - body > next || next != size)  // an empty chain cannot occur (1 x 1 at least): pieces exist
    r.failAt(r.pos(), "TEXS chunk: " + std::to_string(size) + " bytes, its pieces end at " + std::to_string(next));
  // The stored bytes stay in the mapped file (or one copy of them when the caller keeps no mapping).
  std::span<const uint8_t> data = bytes.subspan(body, size);
  std::shared_ptr<const void> keep = owner;
  if (!keep) {
    auto copy = std::make_shared<std::vector<uint8_t>>(data.begin(), data.end());
    data = *copy;
    keep = copy;
  }
  for (uint32_t i = 0; i < count; ++i) {
    baked[i]->data = data;
    baked[i]->owner = keep;
    baked[i]->file = file;
    baked[i]->fileOffset = body;
    scene.textures[i].baked = std::move(baked[i]);
  }
  r.skip(end - r.pos(), "the TEXS pieces");
}

}  // namespace rtr
