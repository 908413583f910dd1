// The OBJ reader on files nobody in the project wrote: where the MTL comes from, what is lenient (names
// in any encoding, empty material names, missing MTLs), and what is refused (not an OBJ, nothing to draw).
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zstd.h>

#include "core/error.hpp"
#include "scene/load.hpp"
#include "scene/obj.hpp"
#include "scene/rtrscene.hpp"

namespace fs = std::filesystem;
using namespace rtr;
using ::testing::HasSubstr;

namespace {

const fs::path kAssimp = "/usr/share/assimp/models";

struct Dir : ::testing::Test {
  fs::path dir = fs::temp_directory_path() / ("rtr_obj_lenient_" + std::to_string(::getpid()));
  std::vector<std::string> warnings, notes;
  LoadOptions opt;
  void SetUp() override {
    fs::remove_all(dir);
    fs::create_directories(dir);
    opt.warn = [this](const std::string& w) { warnings.push_back(w); };
    opt.note = [this](const std::string& n) { notes.push_back(n); };
  }
  void TearDown() override { fs::remove_all(dir); }
  void write(const std::string& name, const std::string& text) { std::ofstream(dir / name, std::ios::binary) << text; }
  Scene load(const std::string& name) { return loadScene(dir / name, opt); }
  std::string errorOf(const fs::path& file) {
    try {
      loadScene(file, opt);
    } catch (const Error& e) { return e.what(); }
    return "(no error)";
  }
  const Material& materialOf(const Scene& s, size_t mesh) { return s.materials.at(s.meshes.at(mesh).material); }
};

// A course-style ray-tracer scene: no mtllib line, a light material.
const char* kLightObj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl light_top\nf 1 2 3\nf 1 3 4\n";
const char* kLightMtl = "newmtl light_top\nKe 1 0.5 0.25\nKd 0 0 0\n";

}  // namespace

TEST_F(Dir, WithoutMtllibTheMtlBesideItIsUsed) {
  write("scene.obj", kLightObj);
  write("scene.mtl", kLightMtl);
  Scene s = load("scene.obj");
  EXPECT_EQ(materialOf(s, 0).ke, glm::vec3(1, 0.5f, 0.25f));
  EXPECT_TRUE(materialOf(s, 0).flags & kMaterialLight);
  EXPECT_TRUE(warnings.empty()) << warnings[0];
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_THAT(notes[0], HasSubstr("no 'mtllib' line; using '" + (dir / "scene.mtl").string() + "'"));
  // NAME.obj.zst and NAME.obj-zstd use NAME.mtl too.
  fs::remove(dir / "scene.obj");
  for (const char* name : {"scene.obj.zst", "scene.obj-zstd"}) {
    std::string z(ZSTD_compressBound(std::strlen(kLightObj)), '\0');
    z.resize(ZSTD_compress(z.data(), z.size(), kLightObj, std::strlen(kLightObj), 1));
    write(name, z);
    EXPECT_EQ(materialOf(load(name), 0).ke, glm::vec3(1, 0.5f, 0.25f)) << name;
  }
}

TEST_F(Dir, WithoutMtllibOrMtlBesideMaterialsAreDefaults) {
  write("scene.obj", kLightObj);
  Scene s = load("scene.obj");
  EXPECT_EQ(materialOf(s, 0).ke, glm::vec3(0.0f));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr("'light_top' is not defined in any MTL"));
}

TEST_F(Dir, GivenMtlReplacesTheMtllibLines) {
  write("scene.obj", std::string("mtllib other.mtl\n") + kLightObj);
  write("other.mtl", "newmtl light_top\nKe 0 0 9\n");
  write("given.mtl", kLightMtl);
  opt.mtl = dir / "given.mtl";
  Scene s = load("scene.obj");
  EXPECT_EQ(materialOf(s, 0).ke, glm::vec3(1, 0.5f, 0.25f));
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_THAT(notes[0], HasSubstr("'mtllib other.mtl' ignored"));
  opt.mtl = dir / "absent.mtl";
  const std::string e = errorOf(dir / "scene.obj");
  EXPECT_THAT(e, HasSubstr("absent.mtl"));
  EXPECT_THAT(e, HasSubstr("does not exist"));
  // Only OBJ scenes take an MTL.
  EXPECT_THAT(errorOf(dir / "x.rtrscene"), HasSubstr("can only be given with an OBJ"));
}

TEST_F(Dir, MissingMtllibFileIsAWarning) {
  write("scene.obj", std::string("mtllib absent.mtl\n") + kLightObj);
  write("scene.mtl", kLightMtl);  // not used: the file has an mtllib line
  Scene s = load("scene.obj");
  EXPECT_EQ(materialOf(s, 0).ke, glm::vec3(0.0f));
  ASSERT_GE(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr("scene.obj:1: material library '" + (dir / "absent.mtl").string() + "'"));
}

TEST_F(Dir, NamesAreBytesInAnyEncoding) {
  // Latin-1 object, material and texture names; the names survive a .rtrscene round trip.
  write("scene.obj", "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\no caf\xe9\nusemtl m\xe9tal\nf 1/1 2/1 3/1\n");
  write("scene.mtl", "newmtl m\xe9tal\nKd 0.5 0.25 1\nmap_Kd tex\xe9.png\n");
  Scene s = load("scene.obj");
  EXPECT_EQ(s.meshes.at(0).name, "caf\xe9");
  EXPECT_EQ(materialOf(s, 0).name, "m\xe9tal");
  EXPECT_EQ(materialOf(s, 0).baseColor, glm::vec3(0.5f, 0.25f, 1));
  EXPECT_EQ(s.textures.at(0).path, "tex\xe9.png");
  EXPECT_TRUE(warnings.empty());
  const std::string bytes = encodeRtrScene(s);
  Scene back = decodeRtrScene(std::span(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()), "x.rtrscene");
  EXPECT_EQ(back.meshes.at(0).name, "caf\xe9");
  EXPECT_EQ(back.materials.at(0).name, "m\xe9tal");
}

TEST_F(Dir, EmptyMaterialNameWarnsAndWorks) {
  write("scene.obj", "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl \nf 1 2 3\n");
  write("scene.mtl", "newmtl \nKd 0.8 0.7 0.6\n");
  Scene s = load("scene.obj");
  EXPECT_EQ(materialOf(s, 0).baseColor, glm::vec3(0.8f, 0.7f, 0.6f));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr("scene.mtl:1: 'newmtl' without a name"));
}

TEST_F(Dir, NotAnObjIsAnErrorNamingTheFile) {
  write("utf16.obj", std::string("\xFE\xFF\0v\0 \0"
                                 "0",
                                 9));
  EXPECT_THAT(errorOf(dir / "utf16.obj"), HasSubstr("utf16.obj: UTF-16 text"));
  write("nul.obj", std::string("v 0 0 0\nv 1 0 0\0\0\0", 18));
  EXPECT_THAT(errorOf(dir / "nul.obj"), HasSubstr("nul.obj: byte 15: control byte 0x00"));
  write("junk.obj", "\x89PNG\r\n\x1a\n\x01\x02junk");
  EXPECT_THAT(errorOf(dir / "junk.obj"), HasSubstr("junk.obj: byte 8: control byte 0x01"));
  write("empty.obj", "");
  EXPECT_THAT(errorOf(dir / "empty.obj"), HasSubstr("empty.obj: no faces"));
  write("text.obj", "Dear reader,\nthis is a letter.\n");
  EXPECT_THAT(errorOf(dir / "text.obj"), HasSubstr("text.obj: no faces"));
  write("bom.obj", "\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");  // UTF-8 byte order mark: fine
  EXPECT_EQ(load("bom.obj").meshes.size(), 1u);
}

TEST_F(Dir, PointsAndLinesAreSkippedWithOneNote) {
  write("pl.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\nl 1 2\nl 2 3\n");
  EXPECT_THAT(errorOf(dir / "pl.obj"), HasSubstr("pl.obj: no faces, only 3 point/line element(s)"));
  write("mixed.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\nl 1 2\nf 1 2 3\nl 2 3\n");
  EXPECT_EQ(load("mixed.obj").meshes.at(0).triangleCount(), 1u);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_THAT(notes[0], HasSubstr("3 point/line element(s) skipped"));
  EXPECT_TRUE(warnings.empty());
}

TEST_F(Dir, WarningsAreCountedNotAllShown) {
  std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  for (int i = 0; i < 25; ++i) obj += "usemtl undefined" + std::to_string(i) + "\nf 1 2 3\n";
  write("many.obj", obj);
  ObjOptions o;
  o.warn = opt.warn;
  ObjStats st;
  loadObj(dir / "many.obj", o, &st);
  EXPECT_EQ(st.warnings, 25u);
  ASSERT_EQ(warnings.size(), 11u);
  EXPECT_THAT(warnings[9], HasSubstr("undefined9"));
  EXPECT_THAT(warnings[10], HasSubstr("many.obj: 25 warnings, first 10 shown"));
}

// Debian's assimp-testmodels: files written by other tools.
TEST(AssimpModels, ReadLikeOtherLoaders) {
  if (!fs::is_directory(kAssimp / "OBJ")) GTEST_SKIP() << "assimp-testmodels is not installed";
  LoadOptions o;
  std::vector<std::string> warnings;
  o.warn = [&](const std::string& w) { warnings.push_back(w); };
  o.note = [](const std::string&) {};
  // Latin-1 material name ("Terraind\xe6k") in the MTL of the spaces test.
  Scene box = loadScene(kAssimp / "OBJ/box_mat_with_spaces.obj", o);
  EXPECT_EQ(box.materials.at(box.meshes.at(0).material).name, "Material name with many, many spaces");
  EXPECT_EQ(box.materials.at(box.meshes.at(0).material).kd, glm::vec3(0.2f));
  // Blender's empty material name.
  Scene cyl = loadScene(kAssimp / "OBJ/empty_mat.obj", o);
  EXPECT_EQ(cyl.materials.at(cyl.meshes.at(0).material).baseColor, glm::vec3(0.8f));
  // mtllib naming a file that is not there.
  warnings.clear();
  EXPECT_EQ(loadScene(kAssimp / "OBJ/cube_mtllib_after_g.obj", o).meshes.at(0).triangleCount(), 12u);
  ASSERT_FALSE(warnings.empty());
  EXPECT_THAT(warnings[0], HasSubstr("cube_mtllib_after_g.mat' named by 'mtllib' does not exist"));
  // The spider: Windows paths to five JPEG textures.
  Scene spider = loadScene(kAssimp / "OBJ/spider.obj", o);
  ASSERT_EQ(spider.textures.size(), 5u);
  for (const Texture& t : spider.textures) EXPECT_TRUE(fs::is_regular_file(spider.baseDir / t.path)) << t.path;
  // Refused, naming the file.
  for (const char* f : {"OBJ/box_UTF16BE.obj", "OBJ/testpoints.obj", "OBJ/testline.obj", "OBJ/point_cloud.obj",
                        "invalid/empty.obj", "invalid/malformed.obj"}) {
    try {
      loadScene(kAssimp / f, o);
      ADD_FAILURE() << f << " accepted";
    } catch (const Error& e) { EXPECT_THAT(e.what(), HasSubstr((kAssimp / f).string())) << f; }
  }
}
