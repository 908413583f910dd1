// The glTF geometry decoders: data encoded here with meshoptimizer's and draco's own encoders comes back,
// and wrong sizes, wrong modes and damaged bytes are errors saying what is wrong, never a crash.
#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include <draco/compression/encode.h>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <meshoptimizer.h>

#include "core/error.hpp"
#include "scene/gltf_compress.hpp"

using namespace rtr;
using ::testing::HasSubstr;

namespace {

template <class T>
std::vector<uint8_t> encodeVertices(const std::vector<T>& v) {
  std::vector<uint8_t> out(meshopt_encodeVertexBufferBound(v.size(), sizeof(T)));
  out.resize(meshopt_encodeVertexBuffer(out.data(), out.size(), v.data(), v.size(), sizeof(T)));
  return out;
}

// A grid's triangles: n×n quads.
std::vector<uint32_t> gridIndices(uint32_t n) {
  std::vector<uint32_t> idx;
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      idx.insert(idx.end(), {a, c, b, b, c, d});
    }
  return idx;
}

std::string meshoptError(std::span<const uint8_t> src, size_t count, size_t stride, const char* mode, const char* filter,
                         size_t outBytes) {
  std::vector<uint8_t> out(outBytes);
  try {
    gltf::decodeMeshopt(src, count, stride, mode, filter, out);
  } catch (const Error& e) { return e.what(); }
  return "(no error)";
}

struct Vertex {
  float x, y, z;
  uint32_t rgba;
};

}  // namespace

TEST(Meshopt, AttributesComeBackExactly) {
  std::vector<Vertex> v;
  std::mt19937 rng(3);
  for (int i = 0; i < 5000; ++i) v.push_back({float(i % 70) * 0.1f, std::sin(float(i)), float(i / 70), uint32_t(rng())});
  const auto src = encodeVertices(v);
  std::vector<Vertex> got(v.size());
  gltf::decodeMeshopt(src, v.size(), sizeof(Vertex), "ATTRIBUTES", "NONE",
                      {reinterpret_cast<uint8_t*>(got.data()), got.size() * sizeof(Vertex)});
  EXPECT_EQ(0, std::memcmp(got.data(), v.data(), v.size() * sizeof(Vertex)));
}

TEST(Meshopt, TrianglesAndIndexSequencesInBothWidths) {
  const std::vector<uint32_t> idx = gridIndices(40);
  std::vector<uint8_t> tri(meshopt_encodeIndexBufferBound(idx.size(), 41 * 41));
  tri.resize(meshopt_encodeIndexBuffer(tri.data(), tri.size(), idx.data(), idx.size()));
  std::vector<uint32_t> seq = idx;
  std::reverse(seq.begin(), seq.end());
  std::vector<uint8_t> seqBytes(meshopt_encodeIndexSequenceBound(seq.size(), 41 * 41));
  seqBytes.resize(meshopt_encodeIndexSequence(seqBytes.data(), seqBytes.size(), seq.data(), seq.size()));
  for (const auto& [mode, src, want] : {std::tuple{"TRIANGLES", tri, idx}, std::tuple{"INDICES", seqBytes, seq}}) {
    SCOPED_TRACE(mode);
    std::vector<uint32_t> got32(want.size());
    gltf::decodeMeshopt(src, want.size(), 4, mode, "NONE", {reinterpret_cast<uint8_t*>(got32.data()), got32.size() * 4});
    EXPECT_EQ(got32, want);
    std::vector<uint16_t> got16(want.size());
    gltf::decodeMeshopt(src, want.size(), 2, mode, "NONE", {reinterpret_cast<uint8_t*>(got16.data()), got16.size() * 2});
    EXPECT_TRUE(std::equal(got16.begin(), got16.end(), want.begin()));
  }
}

// The filters gltfpack uses: octahedral normals, quaternions, exponential floats; each decoded value is
// within the encoding's precision of the original.
TEST(Meshopt, FiltersDecodeToTheEncodedValues) {
  const size_t n = 1000;
  std::vector<float> normals, quats, floats;
  std::mt19937 rng(7);
  std::normal_distribution<float> g;
  for (size_t i = 0; i < n; ++i) {
    glm::vec3 d = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
    normals.insert(normals.end(), {d.x, d.y, d.z, 1.0f});
    glm::vec4 q = glm::normalize(glm::vec4(g(rng), g(rng), g(rng), g(rng)));
    quats.insert(quats.end(), {q.x, q.y, q.z, q.w});
    floats.insert(floats.end(), {g(rng) * 1000.0f, g(rng) * 1e-3f, float(i)});
  }
  struct Case {
    const char* filter;
    size_t stride;
    const std::vector<float>* values;
    int floatsPer;
    double tolerance;
  };
  for (const Case& c : {Case{"OCTAHEDRAL", 8, &normals, 4, 1e-3}, Case{"QUATERNION", 8, &quats, 4, 1e-3},
                        Case{"EXPONENTIAL", 12, &floats, 3, 1e-6}}) {
    SCOPED_TRACE(c.filter);
    std::vector<uint8_t> filtered(n * c.stride);
    if (c.stride == 8 && std::string(c.filter) == "OCTAHEDRAL")
      meshopt_encodeFilterOct(filtered.data(), n, 8, 16, c.values->data());
    if (std::string(c.filter) == "QUATERNION") meshopt_encodeFilterQuat(filtered.data(), n, 8, 16, c.values->data());
    if (std::string(c.filter) == "EXPONENTIAL") meshopt_encodeFilterExp(filtered.data(), n, 12, 24, c.values->data());
    std::vector<uint8_t> src(meshopt_encodeVertexBufferBound(n, c.stride));
    src.resize(meshopt_encodeVertexBuffer(src.data(), src.size(), filtered.data(), n, c.stride));
    std::vector<uint8_t> out(n * c.stride);
    gltf::decodeMeshopt(src, n, c.stride, "ATTRIBUTES", c.filter, out);
    double worst = 0;
    for (size_t i = 0; i < n; ++i) {
      const float* want = c.values->data() + i * c.floatsPer;
      if (c.stride == 8) {  // 16-bit snorm components
        const int16_t* q = reinterpret_cast<const int16_t*>(out.data() + i * 8);
        const float sign = std::string(c.filter) == "QUATERNION" && (q[3] < 0) != (want[3] < 0) ? -1.0f : 1.0f;  // q and -q
        for (int k = 0; k < 3; ++k) worst = std::max(worst, double(std::abs(sign * float(q[k]) / 32767.0f - want[k])));
      } else {
        // 24-bit mantissas under one exponent per vector (meshoptimizer 0.18): relative to the largest component.
        const float* f = reinterpret_cast<const float*>(out.data() + i * 12);
        const float scale = std::max({std::abs(want[0]), std::abs(want[1]), std::abs(want[2])});
        for (int k = 0; k < 3; ++k) worst = std::max(worst, double(std::abs(f[k] - want[k]) / scale));
      }
    }
    EXPECT_LT(worst, c.tolerance);
    EXPECT_GT(worst, 0.0);  // really filtered (lossy), not copied
  }
}

TEST(Meshopt, WrongSizesModesAndDamagedBytesAreErrors) {
  std::vector<Vertex> v(300, Vertex{1, 2, 3, 4});
  for (size_t i = 0; i < v.size(); ++i) v[i].x = float(i);
  const auto src = encodeVertices(v);
  const size_t bytes = v.size() * 16;
  EXPECT_EQ(meshoptError(src, 300, 16, "ATTRIBUTES", "NONE", bytes), "(no error)");
  EXPECT_THAT(meshoptError(src, 300, 16, "ATTRIBUTES", "NONE", bytes - 16), HasSubstr("is not the 4784 bytes"));
  EXPECT_THAT(meshoptError(src, size_t(1) << 62, 16, "ATTRIBUTES", "NONE", bytes), HasSubstr("is not the"));
  EXPECT_THAT(meshoptError(src, 300, 0, "ATTRIBUTES", "NONE", bytes), HasSubstr("byteStride 0"));
  EXPECT_THAT(meshoptError(src, 400, 12, "ATTRIBUTES", "NONE", bytes), HasSubstr("do not decode as ATTRIBUTES"));
  EXPECT_THAT(meshoptError(src, 1, 260, "ATTRIBUTES", "NONE", 260), HasSubstr("not a multiple of 4 up to 256"));
  EXPECT_THAT(meshoptError(src, 2, 6, "ATTRIBUTES", "NONE", 12), HasSubstr("not a multiple of 4"));
  EXPECT_THAT(meshoptError(src, 300, 16, "ATTRIBUTES", "OCTAHEDRAL", bytes), HasSubstr("(must be 4 or 8)"));
  EXPECT_THAT(meshoptError(src, 300, 16, "ATTRIBUTES", "QUATERNION", bytes), HasSubstr("(must be 8)"));
  EXPECT_THAT(meshoptError(src, 300, 16, "ATTRIBUTES", "SHARPEN", bytes), HasSubstr("unknown filter 'SHARPEN'"));
  EXPECT_THAT(meshoptError(src, 300, 16, "POINTS", "NONE", bytes), HasSubstr("unknown mode 'POINTS'"));
  EXPECT_THAT(meshoptError(src, 300, 4, "TRIANGLES", "EXPONENTIAL", 1200), HasSubstr("filters apply to ATTRIBUTES only"));
  EXPECT_THAT(meshoptError(src, 300, 8, "INDICES", "NONE", 2400), HasSubstr("neither 2 nor 4"));
  EXPECT_THAT(meshoptError(src, 301, 4, "TRIANGLES", "NONE", 1204), HasSubstr("not a multiple of 3"));
  EXPECT_THAT(meshoptError(src, 300, 4, "TRIANGLES", "NONE", 1200), HasSubstr("do not decode as TRIANGLES"));
  // Truncated at every length: an error, never a read past the input (ASan builds check the "never").
  for (size_t cut = 0; cut < src.size(); cut += 7)
    EXPECT_THAT(meshoptError(std::span(src).first(cut), 300, 16, "ATTRIBUTES", "NONE", bytes), HasSubstr("do not decode"));
  // Random bytes in every mode: decoded (garbage) or refused, nothing else.
  std::mt19937 rng(11);
  for (int i = 0; i < 300; ++i) {
    std::vector<uint8_t> junk(rng() % 600);
    for (uint8_t& b : junk) b = uint8_t(rng());
    if (!junk.empty()) junk[0] = uint8_t(0xa0 | (rng() & 1) << 4);  // the right header nibble, so decoding starts
    for (const char* mode : {"ATTRIBUTES", "TRIANGLES", "INDICES"}) {
      const std::string e = meshoptError(junk, 30, 4, mode, "NONE", 120);
      EXPECT_TRUE(e == "(no error)" || e.find("do not decode") != std::string::npos) << e;
    }
  }
}

namespace {

// A small closed mesh (an octahedron subdivided once) encoded by draco with or without quantization.
struct DracoSource {
  std::vector<std::array<glm::vec3, 3>> triangles;
  std::vector<uint8_t> bytes;
  int positionId = -1, normalId = -1, uvId = -1;
};

DracoSource dracoSource(int quantizationBits) {
  DracoSource s;
  const glm::vec3 c[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const int faces[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (const auto& f : faces) {
    const glm::vec3 a = c[f[0]], b = c[f[1]], d = c[f[2]];
    const glm::vec3 ab = glm::normalize(a + b), bd = glm::normalize(b + d), da = glm::normalize(d + a);
    for (const auto& t : {std::array{a, ab, da}, std::array{ab, b, bd}, std::array{da, bd, d}, std::array{ab, bd, da}})
      s.triangles.push_back(t);
  }
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(int(s.triangles.size()));
  const int pos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int nrm = builder.AddAttribute(draco::GeometryAttribute::NORMAL, 3, draco::DT_FLOAT32);
  const int uv = builder.AddAttribute(draco::GeometryAttribute::TEX_COORD, 2, draco::DT_FLOAT32);
  for (size_t f = 0; f < s.triangles.size(); ++f) {
    const auto& t = s.triangles[f];
    const glm::vec2 uvs[3] = {{t[0].x, t[0].z}, {t[1].x, t[1].z}, {t[2].x, t[2].z}};
    builder.SetAttributeValuesForFace(pos, draco::FaceIndex(uint32_t(f)), &t[0], &t[1], &t[2]);
    builder.SetAttributeValuesForFace(nrm, draco::FaceIndex(uint32_t(f)), &t[0], &t[1], &t[2]);
    builder.SetAttributeValuesForFace(uv, draco::FaceIndex(uint32_t(f)), &uvs[0], &uvs[1], &uvs[2]);
  }
  std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  draco::Encoder encoder;
  if (quantizationBits > 0) encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, quantizationBits);
  draco::EncoderBuffer out;
  EXPECT_TRUE(encoder.EncodeMeshToBuffer(*mesh, &out).ok());
  s.bytes.assign(out.data(), out.data() + out.size());
  s.positionId = int(mesh->attribute(pos)->unique_id());
  s.normalId = int(mesh->attribute(nrm)->unique_id());
  s.uvId = int(mesh->attribute(uv)->unique_id());
  return s;
}

std::string dracoError(std::span<const uint8_t> src, const std::vector<std::pair<std::string, int>>& attributes) {
  try {
    gltf::decodeDraco(src, attributes);
  } catch (const Error& e) { return e.what(); }
  return "(no error)";
}

// Each triangle with its corners rotated to start at the smallest: the same set whatever order draco
// gives the vertices in.
std::vector<std::array<float, 9>> canonical(const std::vector<std::array<glm::vec3, 3>>& tris) {
  std::vector<std::array<float, 9>> out;
  for (const auto& t : tris) {
    auto key = [&](int k) { return std::array{t[k].x, t[k].y, t[k].z}; };
    int first = 0;
    for (int k = 1; k < 3; ++k)
      if (key(k) < key(first)) first = k;
    std::array<float, 9> c;
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) c[size_t(k * 3 + j)] = t[(first + k) % 3][j];
    out.push_back(c);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST(Draco, MeshComesBackWithItsAttributes) {
  const DracoSource s = dracoSource(0);  // no quantization: lossless
  const gltf::DracoMesh m =
      gltf::decodeDraco(s.bytes, {{"POSITION", s.positionId}, {"TEXCOORD_0", s.uvId}, {"NORMAL", s.normalId}});
  ASSERT_EQ(m.attributes.size(), 3u);
  EXPECT_EQ(m.attributes[0].name, "POSITION");
  EXPECT_EQ(m.attributes[0].components, 3);
  EXPECT_EQ(m.attributes[1].name, "TEXCOORD_0");
  EXPECT_EQ(m.attributes[1].components, 2);
  ASSERT_EQ(m.indices.size(), s.triangles.size() * 3);
  ASSERT_EQ(m.attributes[0].values.size(), size_t(m.vertexCount) * 3);
  EXPECT_LE(m.vertexCount, 18u);  // corners shared: the builder's 96 corners weld to the 18 distinct vertices
  std::vector<std::array<glm::vec3, 3>> got;
  const float* p = m.attributes[0].values.data();
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    std::array<glm::vec3, 3> tri;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = m.indices[t + size_t(k)];
      ASSERT_LT(v, m.vertexCount);
      tri[size_t(k)] = {p[v * 3], p[v * 3 + 1], p[v * 3 + 2]};
      EXPECT_EQ(m.attributes[1].values[v * 2], tri[size_t(k)].x);  // each vertex's uv is its (x, z)
      EXPECT_EQ(m.attributes[1].values[v * 2 + 1], tri[size_t(k)].z);
    }
    got.push_back(tri);
  }
  EXPECT_EQ(canonical(got), canonical(s.triangles));
}

TEST(Draco, QuantizedPositionsComeBackWithinTheirPrecision) {
  const DracoSource s = dracoSource(11);
  const gltf::DracoMesh m = gltf::decodeDraco(s.bytes, {{"POSITION", s.positionId}});
  ASSERT_EQ(m.indices.size(), s.triangles.size() * 3);
  float worst = 0;
  for (uint32_t v = 0; v < m.vertexCount; ++v) {
    const glm::vec3 q{m.attributes[0].values[v * 3], m.attributes[0].values[v * 3 + 1], m.attributes[0].values[v * 3 + 2]};
    float nearest = 1e9f;  // distance to the nearest original corner
    for (const auto& t : s.triangles)
      for (const glm::vec3& c : t) nearest = std::min(nearest, glm::length(q - c));
    worst = std::max(worst, nearest);
  }
  EXPECT_LT(worst, 2.0f / 2047.0f);  // the 2-unit box in 11 bits
  EXPECT_GT(worst, 0.0f);
}

TEST(Draco, MissingAttributesAndDamagedBytesAreErrors) {
  const DracoSource s = dracoSource(0);
  EXPECT_THAT(dracoError(s.bytes, {{"COLOR_0", 9}}), HasSubstr("attribute COLOR_0 names id 9, which the data does not have"));
  EXPECT_THAT(dracoError(s.bytes, {{"COLOR_0", -1}}), HasSubstr("names id -1"));
  EXPECT_THAT(dracoError({}, {{"POSITION", 0}}), HasSubstr("draco: "));
  for (size_t cut = 0; cut < s.bytes.size(); cut += 5) {
    const std::string e = dracoError(std::span(s.bytes).first(cut), {{"POSITION", s.positionId}});
    EXPECT_THAT(e, HasSubstr("draco: ")) << "cut at " << cut;
  }
  std::mt19937 rng(5);
  for (int i = 0; i < 300; ++i) {
    std::vector<uint8_t> b = s.bytes;
    for (int k = 0; k < 3; ++k) b[rng() % b.size()] ^= uint8_t(1u << (rng() % 8));
    const std::string e = dracoError(b, {{"POSITION", s.positionId}});
    EXPECT_TRUE(e == "(no error)" || e.find("draco: ") != std::string::npos) << e;
  }
}
