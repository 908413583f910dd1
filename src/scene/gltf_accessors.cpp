#include "scene/gltf_accessors.hpp"

#include <cstring>
#include <limits>
#include <type_traits>

#include "scene/binio.hpp"
#include "scene/gltf_compress.hpp"

namespace rtr::gltf {

namespace {

std::string bytes(uint64_t n) { return std::to_string(n) + (n == 1 ? " byte" : " bytes"); }

int componentSize(uint32_t type) {
  switch (type) {
    case 5120:
    case 5121: return 1;
    case 5122:
    case 5123: return 2;
    case 5125:
    case 5126: return 4;
    default: return 0;
  }
}

int typeComponents(std::string_view t) {
  if (t == "SCALAR") return 1;
  if (t == "VEC2") return 2;
  if (t == "VEC3") return 3;
  if (t == "VEC4") return 4;
  if (t == "MAT2") return 4;
  if (t == "MAT3") return 9;
  if (t == "MAT4") return 16;
  return 0;
}

// One component as a float: normalized integers to [0,1] or [-1,1] (the spec's rules), others as they are.
template <class T, bool Normalized>
float component(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  if constexpr (!Normalized || std::is_floating_point_v<T>) {
    return float(v);
  } else if constexpr (std::is_signed_v<T>) {
    return std::max(float(v) / float(std::numeric_limits<T>::max()), -1.0f);
  } else {
    return float(double(v) / double(std::numeric_limits<T>::max()));
  }
}

// Converts `count` elements of `comps` components (element i at p + i * stride) to floats at dst, `dc`
// floats apart: one loop per component type, no switch per value.
template <class T, bool Normalized>
void convertAs(const uint8_t* p, size_t stride, uint32_t count, int comps, float* dst, int dc) {
  for (uint32_t i = 0; i < count; ++i)
    for (int c = 0; c < comps; ++c) dst[size_t(i) * dc + c] = component<T, Normalized>(p + size_t(i) * stride + c * sizeof(T));
}
template <bool Normalized>
void convertN(uint32_t type, const uint8_t* p, size_t stride, uint32_t count, int comps, float* dst, int dc) {
  switch (type) {
    case 5120: return convertAs<int8_t, Normalized>(p, stride, count, comps, dst, dc);
    case 5121: return convertAs<uint8_t, Normalized>(p, stride, count, comps, dst, dc);
    case 5122: return convertAs<int16_t, Normalized>(p, stride, count, comps, dst, dc);
    case 5123: return convertAs<uint16_t, Normalized>(p, stride, count, comps, dst, dc);
    case 5125: return convertAs<uint32_t, Normalized>(p, stride, count, comps, dst, dc);
    default: return convertAs<float, false>(p, stride, count, comps, dst, dc);
  }
}
void convert(uint32_t type, bool normalized, const uint8_t* p, size_t stride, uint32_t count, int comps, float* dst, int dc) {
  if (normalized) convertN<true>(type, p, stride, count, comps, dst, dc);
  else convertN<false>(type, p, stride, count, comps, dst, dc);
}

uint32_t toIndex(const uint8_t* p, uint32_t type) {
  switch (type) {
    case 5121: return *p;
    case 5123: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    default: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

int base64Value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+' || c == '-') return 62;
  if (c == '/' || c == '_') return 63;
  return -1;
}

// A file an accessor may read from must fit what it claims: no more zeros or decoded bytes than this
// from a view without data or a compressed view (a few bytes of JSON must not claim gigabytes).
constexpr uint64_t kMaxUnbackedElements = uint64_t(1) << 26;

}  // namespace

std::optional<std::vector<uint8_t>> decodeBase64(std::string_view s) {
  while (!s.empty() && s.back() == '=') s.remove_suffix(1);
  std::vector<uint8_t> out;
  out.reserve(s.size() / 4 * 3 + 3);
  uint32_t acc = 0;
  int bits = 0;
  for (char c : s) {
    const int v = base64Value(c);
    if (v < 0) return std::nullopt;
    acc = (acc << 6) | uint32_t(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(uint8_t(acc >> bits));
    }
  }
  if (bits >= 6) return std::nullopt;  // one character left over: not whole bytes
  return out;
}

std::vector<uint8_t> decodeDataUri(const Json& where, std::string_view uri) {
  const size_t comma = uri.find(',');
  if (uri.substr(0, 5) != "data:" || comma == std::string_view::npos) where.fail("not a data URI (no ',')");
  const std::string_view head = uri.substr(5, comma - 5);
  if (head.size() < 7 || head.substr(head.size() - 7) != ";base64")
    where.fail("only base64 data URIs are supported ('" + std::string(head) + "')");
  auto d = decodeBase64(uri.substr(comma + 1));
  if (!d) where.fail("the data URI's base64 payload is not valid base64");
  return std::move(*d);
}

std::string uriToPath(std::string_view uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    auto hex = [](char c) {
      return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
    };
    if (uri[i] == '%' && i + 2 < uri.size() + 0 && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
      out += char(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

Accessors::Accessors(const Json& root, std::filesystem::path baseDir, std::span<const uint8_t> glbBin, bool isGlb)
    : root_(root), baseDir_(std::move(baseDir)), glbBin_(glbBin), isGlb_(isGlb) {
  auto list = [&](const char* key, std::vector<Json>& out) {
    if (auto a = root.get(key))
      for (size_t i = 0, n = a->size(); i < n; ++i) out.push_back((*a)[i]);
  };
  list("buffers", buffersJ_);
  list("bufferViews", views_);
  list("accessors", accessors_);
  buffers_.resize(buffersJ_.size());
  decodedViews_.resize(views_.size());
}

Accessors::~Accessors() = default;

std::span<const uint8_t> Accessors::buffer(uint32_t i) {
  if (buffers_[i]) return *buffers_[i];
  const Json& b = buffersJ_[i];
  const Json lenJ = b.at("byteLength");
  const uint64_t length = lenJ.uinteger();
  std::span<const uint8_t> data;
  if (auto uri = b.get("uri")) {
    const std::string_view u = uri->string();
    if (u.substr(0, 5) == "data:") {
      owned_.push_back(decodeDataUri(*uri, u));
      data = owned_.back();
    } else {
      const std::filesystem::path file = baseDir_ / uriToPath(u);
      try {
        mapped_.push_back(std::make_unique<MappedFile>(file));
      } catch (const Error& e) { uri->fail(e.what()); }
      data = mapped_.back()->bytes();
    }
  } else if (isGlb_ && i == 0) {
    data = glbBin_;
    if (data.empty()) b.fail("uses the GLB's BIN chunk, which the file does not have");
  } else {
    b.fail(b.get("extensions") ? "has no data (a compression extension's fallback buffer that is read)"
                               : "has no uri and is not the GLB's BIN chunk");
  }
  if (length > data.size()) lenJ.fail(bytes(length) + ", but the buffer's data has only " + bytes(data.size()));
  buffers_[i] = data.first(size_t(length));
  return *buffers_[i];
}

std::span<const uint8_t> Accessors::view(uint32_t i) {
  if (decodedViews_[i]) return *decodedViews_[i];
  const Json& v = views_[i];
  const Json lenJ = v.at("byteLength");
  const uint64_t length = lenJ.uinteger();
  if (auto ext = v.get("extensions"); ext && ext->get("EXT_meshopt_compression")) {
    const Json m = ext->at("EXT_meshopt_compression");
    const std::span<const uint8_t> buf = buffer(m.index("buffer", buffersJ_.size(), "buffers"));
    const uint64_t off = m.uinteger("byteOffset", 0), len = m.at("byteLength").uinteger();
    if (off > buf.size() || len > buf.size() - off)
      m.fail("byteOffset " + std::to_string(off) + " + byteLength " + std::to_string(len) + " run past the end of its buffer (" +
             bytes(buf.size()) + ")");
    const uint64_t count = m.at("count").uinteger(), stride = m.at("byteStride").uinteger();
    if (stride == 0 || stride > 256) m.at("byteStride").fail("must be 1..256, is " + std::to_string(stride));
    if (count > kMaxUnbackedElements || count * stride > (len + 1024) * 256)
      m.at("count").fail(std::to_string(count) + " elements cannot come out of " + bytes(len) + " of compressed data");
    if (count * stride < length)
      lenJ.fail(bytes(length) + ", more than the " + bytes(count * stride) + " the compressed data decodes to");
    std::vector<uint8_t> out(size_t(count * stride));
    try {
      decodeMeshopt(buf.subspan(size_t(off), size_t(len)), size_t(count), size_t(stride), m.string("mode", ""),
                    m.string("filter", "NONE"), out);
    } catch (const Error& e) { m.fail(e.what()); }
    out.resize(size_t(length));
    decodedViews_[i] = std::move(out);
    return *decodedViews_[i];
  }
  const std::span<const uint8_t> buf = buffer(v.index("buffer", buffersJ_.size(), "buffers"));
  const uint64_t off = v.uinteger("byteOffset", 0);
  if (off > buf.size() || length > buf.size() - off)
    v.fail("byteOffset " + std::to_string(off) + " + byteLength " + std::to_string(length) + " run past the end of buffer " +
           std::to_string(v.uinteger("buffer", 0)) + " (" + bytes(buf.size()) + ")");
  return buf.subspan(size_t(off), size_t(length));
}

Accessors::Info Accessors::info(uint32_t accessor) const {
  const Json& a = accessors_[accessor];
  Info r;
  const Json ct = a.at("componentType");
  r.componentType = uint32_t(std::min<uint64_t>(ct.uinteger(), 0xFFFFFFFFu));
  if (!componentSize(r.componentType))
    ct.fail(std::to_string(r.componentType) + " is not a component type (5120, 5121, 5122, 5123, 5125, 5126)");
  const Json type = a.at("type");
  r.components = typeComponents(type.string());
  if (!r.components) type.fail("'" + std::string(type.string()) + "' is not an accessor type");
  const Json count = a.at("count");
  const uint64_t n = count.uinteger();
  if (n == 0 || n > 0xFFFFFFFFu) count.fail(std::to_string(n) + " is not an element count (1..2^32-1)");
  r.count = uint32_t(n);
  r.normalized = a.boolean("normalized", false);
  if (r.normalized && (r.componentType == 5126 || r.componentType == 5125))
    a.at("normalized").fail("only byte and short components can be normalized");
  return r;
}

Accessors::Range Accessors::range(const Json& a, uint32_t viewIndex, uint64_t byteOffset, uint64_t count, size_t elemSize,
                                  bool viewStrideAllowed) {
  const std::span<const uint8_t> v = view(viewIndex);
  size_t stride = elemSize;
  if (auto s = views_[viewIndex].get("byteStride"); s && viewStrideAllowed) {
    const uint64_t st = s->uinteger();
    if (st < 4 || st > 252 || st % 4) s->fail(std::to_string(st) + " is not a byte stride (a multiple of 4 in 4..252)");
    if (st < elemSize) s->fail(std::to_string(st) + " is less than the " + bytes(elemSize) + " of one element of " + a.path());
    stride = size_t(st);
  }
  // offset + (count - 1) * stride + elemSize <= view size, without overflow (count < 2^32, stride < 2^8).
  const uint64_t span = (count - 1) * stride + elemSize;
  if (byteOffset > v.size() || span > v.size() - byteOffset)
    a.fail("byteOffset " + std::to_string(byteOffset) + " + " + bytes(span) + " of elements run past the end of bufferView " +
           std::to_string(viewIndex) + " (" + bytes(v.size()) + ")");
  return {v.subspan(size_t(byteOffset)), stride};
}

template <class Write>
void Accessors::forEach(uint32_t accessor, const Info& in, Write&& write) {
  const Json& a = accessors_[accessor];
  const size_t elemSize = size_t(componentSize(in.componentType)) * size_t(in.components);
  if (a.get("bufferView")) {
    const uint32_t vi = a.index("bufferView", views_.size(), "bufferViews");
    const Range r = range(a, vi, a.uinteger("byteOffset", 0), in.count, elemSize, true);
    write.all(r.data.data(), r.stride);
  } else {
    if (in.count > kMaxUnbackedElements)
      a.at("count").fail(std::to_string(in.count) + " elements with no bufferView (zeros) is more than this reader takes");
    write.zeros();
  }
  auto sparse = a.get("sparse");
  if (!sparse) return;
  const Json cnt = sparse->at("count");
  const uint64_t n = cnt.uinteger();
  if (n == 0 || n > in.count) cnt.fail(std::to_string(n) + " is not 1.." + std::to_string(in.count));
  const Json idx = sparse->at("indices"), val = sparse->at("values");
  const uint32_t idxType = uint32_t(std::min<uint64_t>(idx.at("componentType").uinteger(), 0xFFFFFFFFu));
  if (idxType != 5121 && idxType != 5123 && idxType != 5125)
    idx.at("componentType").fail("sparse indices must be 5121, 5123 or 5125");
  const Range ir = range(idx, idx.index("bufferView", views_.size(), "bufferViews"), idx.uinteger("byteOffset", 0), n,
                         size_t(componentSize(idxType)), false);
  const Range vr =
      range(val, val.index("bufferView", views_.size(), "bufferViews"), val.uinteger("byteOffset", 0), n, elemSize, false);
  for (uint64_t k = 0; k < n; ++k) {
    const uint32_t i = toIndex(ir.data.data() + k * ir.stride, idxType);
    if (i >= in.count)
      idx.fail("sparse index " + std::to_string(i) + " (element " + std::to_string(k) + ") is not below the accessor's count " +
               std::to_string(in.count));
    write.one(i, vr.data.data() + k * vr.stride);
  }
}

void Accessors::prepare(uint32_t accessor) {
  const Json& a = accessors_[accessor];
  if (a.get("bufferView")) view(a.index("bufferView", views_.size(), "bufferViews"));
  if (auto sparse = a.get("sparse"))
    for (const char* part : {"indices", "values"}) {
      const Json j = sparse->at(part);
      view(j.index("bufferView", views_.size(), "bufferViews"));
    }
}

void Accessors::readFloats(uint32_t accessor, float* dst, int dstComponents, std::initializer_list<int> allowed) {
  const Info in = info(accessor);
  if (std::find(allowed.begin(), allowed.end(), in.components) == allowed.end()) {
    std::string list;
    for (int c : allowed) list += std::string(list.empty() ? "" : " or ") + (c == 1 ? "SCALAR" : "VEC" + std::to_string(c));
    accessors_[accessor].at("type").fail("'" + std::string(accessors_[accessor].string("type", "")) + "' where " + list +
                                         " is expected");
  }
  const int comps = std::min(in.components, dstComponents);
  struct {
    float* dst;
    int dc, comps;
    uint32_t count, type;
    bool norm;
    void one(uint32_t i, const uint8_t* p) const { convert(type, norm, p, 0, 1, comps, dst + size_t(i) * dc, dc); }
    void all(const uint8_t* p, size_t stride) const {
      if (type == 5126 && comps == dc && stride == size_t(4 * dc)) {  // the layout matches: one copy, no conversion
        std::memcpy(dst, p, size_t(count) * stride);
        return;
      }
      convert(type, norm, p, stride, count, comps, dst, dc);
    }
    void zeros() const {
      for (uint32_t i = 0; i < count; ++i)
        for (int c = 0; c < comps; ++c) dst[size_t(i) * dc + c] = 0.0f;
    }
  } w{dst, dstComponents, comps, in.count, in.componentType, in.normalized};
  forEach(accessor, in, w);
}

void Accessors::readIndices(uint32_t accessor, std::vector<uint32_t>& out) {
  const Info in = info(accessor);
  const Json& a = accessors_[accessor];
  if (in.components != 1) a.at("type").fail("indices must be SCALAR");
  if (in.componentType != 5121 && in.componentType != 5123 && in.componentType != 5125)
    a.at("componentType").fail("indices must be unsigned (5121, 5123 or 5125)");
  out.resize(in.count);
  struct {
    uint32_t* dst;
    uint32_t count, type;
    void one(uint32_t i, const uint8_t* p) const { dst[i] = toIndex(p, type); }
    void all(const uint8_t* p, size_t stride) const {
      if (type == 5125 && stride == 4) {
        std::memcpy(dst, p, size_t(count) * 4);
        return;
      }
      for (uint32_t i = 0; i < count; ++i) one(i, p + size_t(i) * stride);
    }
    void zeros() const { std::fill(dst, dst + count, 0u); }
  } w{out.data(), in.count, in.componentType};
  forEach(accessor, in, w);
}

}  // namespace rtr::gltf
