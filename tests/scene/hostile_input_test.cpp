// Input that cannot be trusted (issue 33): huge and non-finite coordinates, inputs that are not regular
// files, material libraries that never end. Each is a prompt error naming the file and the place.
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/bounds.hpp"
#include "core/error.hpp"
#include "scene/clusters.hpp"
#include "scene/course.hpp"
#include "scene/load.hpp"
#include "scene/obj.hpp"

namespace fs = std::filesystem;
using ::testing::HasSubstr;

namespace rtr {
namespace {

struct Hostile : ::testing::Test {
  fs::path dir = fs::temp_directory_path() / ("rtr_hostile_" + std::to_string(::getpid()));
  void SetUp() override { fs::create_directories(dir); }
  void TearDown() override { fs::remove_all(dir); }
  fs::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir / name, std::ios::binary) << text;
    return dir / name;
  }
  std::string loadError(const fs::path& file, const LoadOptions& o = {}) {
    try {
      loadScene(file, o);
    } catch (const Error& e) { return e.what(); }
    return "(no error)";
  }
};

// The review's 6-line OBJ: a vertex at -1e38 aborted every tool inside meshoptimizer's clusterizer; 1e20
// was "clustering lost triangles" with no file named.
TEST_F(Hostile, HugeCoordinatesAreRefusedWithFileAndLine) {
  for (const char* y : {"-1e38", "1e20", "-3.4e38", "1.5e12"}) {
    const fs::path f = write("a.obj", std::string("v -9.2336 -8.6416 0.9305\nv 8.7054 ") + y +
                                          " 9.3573\nv 3.0998 3.5073 -3.2027\nv 6.0128 -7.7502 -4.4509\nf 1 2 3\nf 1 3 4\n");
    EXPECT_THAT(loadError(f), HasSubstr("a.obj:2: vertex coordinate beyond ±1e12")) << y;
  }
  const fs::path ok = write("b.obj", "v 0 0 0\nv 1e12 0 0\nv 0 -1e12 1e12\nf 1 2 3\n");
  EXPECT_EQ(loadError(ok), "(no error)");
}

// Whatever a reader lets through, meshoptimizer never sees a coordinate it would assert on.
TEST_F(Hostile, ClusteringRefusesWhatMeshoptimizerWouldAbortOn) {
  Mesh m;
  m.name = "m";
  m.positions = {{-9.2336f, -8.6416f, 0.9305f}, {8.7054f, -1e38f, 9.3573f}, {3.0998f, 3.5073f, -3.2027f}};
  m.indices = {0, 1, 2};
  try {
    buildClusters(m, true);
    ADD_FAILURE() << "clustered";
  } catch (const Error& e) { EXPECT_THAT(e.what(), HasSubstr("mesh 'm': position 1 is not finite or beyond ±1e12")); }
  m.positions.writable()[1].y = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(buildClusters(m, true), Error);
}

// Up to the limit, with tiny and huge values mixed, clustering keeps every triangle and aborts nowhere:
// the limit is where meshoptimizer's arithmetic is still finite.
TEST_F(Hostile, ClusteringIsSafeUpToTheCoordinateLimit) {
  std::mt19937 rng(33);
  for (int round = 0; round < 40; ++round) {
    Mesh m;
    m.name = "r";
    const float scale = round % 2 ? kMaxCoordinate : std::pow(10.0f, float(round % 13));
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int i = 0; i < 300; ++i) {
      glm::vec3 p{u(rng), u(rng), u(rng)};
      for (int k = 0; k < 3; ++k) p[k] = rng() % 4 == 0 ? (rng() % 2 ? kMaxCoordinate : -kMaxCoordinate) : p[k] * scale;
      if (rng() % 7 == 0) p = glm::vec3(0.0f);
      m.positions.push_back(p);
    }
    for (int t = 0; t < 400; ++t)
      for (int k = 0; k < 3; ++k) m.indices.push_back(uint32_t(rng() % m.positions.size()));
    ASSERT_NO_THROW(buildClusters(m, round % 3 != 0)) << "round " << round;
    size_t triangles = 0;
    for (const Cluster& c : m.clusters) triangles += c.triangleCount;
    EXPECT_EQ(triangles, 400u) << "round " << round;
  }
}

// A course file with a huge position: its byte offset, before clustering.
TEST_F(Hostile, CourseMeshCoordinateLimitNamesTheByte) {
  Scene s;
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 2e15f, 0}};
  m.normals.assign(3, glm::vec3(0, 0, 1));
  m.texcoords.assign(3, glm::vec2(0));
  m.indices = {0, 1, 2};
  s.meshes.push_back(m);
  s.materials.emplace_back();
  const std::string bytes = encodeCourseMesh(s);
  std::ofstream(dir / "x.comp5892mesh", std::ios::binary) << bytes;
  EXPECT_THAT(loadError(dir / "x.comp5892mesh"),
              ::testing::MatchesRegex(".*x\\.comp5892mesh: byte [0-9]+: mesh 0: position 2 is beyond.*"));
}

// A FIFO as scene, as --mtl and as mtllib; /dev/zero as --mtl and as mtllib: errors at once, naming them.
TEST_F(Hostile, FifosAndDevicesAreRefusedPromptly) {
  const fs::path fifo = dir / "pipe.obj";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path obj = write("s.obj", "mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const fs::path fifoLib = write("t.obj", "mtllib pipe.obj\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  LoadOptions devZero, fifoMtl;
  devZero.mtl = "/dev/zero";
  fifoMtl.mtl = fifo;
  const auto t0 = std::chrono::steady_clock::now();
  // Without the fix the first would block forever: ctest's timeout then fails it.
  EXPECT_THAT(loadError(fifo), HasSubstr("pipe.obj: a FIFO (named pipe), not a regular file"));
  EXPECT_THAT(loadError(obj), HasSubstr("/dev/zero: a character device, not a regular file"));
  EXPECT_THAT(loadError(write("u.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), devZero),
              HasSubstr("/dev/zero: a character device"));
  EXPECT_THAT(loadError(fifoLib), HasSubstr("pipe.obj: a FIFO"));
  EXPECT_THAT(loadError(write("v.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), fifoMtl), HasSubstr("pipe.obj: a FIFO"));
  EXPECT_THAT(loadError("/dev/zero"), HasSubstr("/dev/zero"));
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(10));
}

// A 4 GiB .comp5892mesh whose magic is wrong is refused from its header, not read whole first.
TEST_F(Hostile, LargeFileWithBadHeaderIsNotReadWhole) {
  const fs::path f = dir / "big.comp5892mesh";
  std::ofstream(f, std::ios::binary) << "not a mesh";
  fs::resize_file(f, uint64_t(4) << 30);  // sparse
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_THAT(loadError(f), HasSubstr("big.comp5892mesh: byte 0: not a .comp5892mesh file"));
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));
}

}  // namespace
}  // namespace rtr
