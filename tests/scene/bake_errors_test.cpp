// rtr-bake's bad-input cases: each gets a clear error, and nothing is left behind.
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "bake.hpp"
#include "core/error.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using ::testing::HasSubstr;

namespace {

struct Fixture : ::testing::Test {
  fs::path dir = fs::temp_directory_path() / ("rtr_bake_err_" + std::to_string(::getpid()));
  fs::path out = dir / "out";
  void SetUp() override {
    fs::remove_all(dir);
    fs::create_directories(out);
    write("s.obj", "mtllib s.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
    write("s.mtl", "newmtl a\nmap_Kd tex.png\n");
    fs::copy_file(rtr::test::sourceDir() / "assets-src/temple/textures/gold_col.png", dir / "tex.png");
  }
  void TearDown() override { fs::remove_all(dir); }
  void write(const std::string& name, const std::string& text) { std::ofstream(dir / name, std::ios::binary) << text; }
  std::string bakeError(const fs::path& output, bool force = false) {
    rtr::BakeOptions o{dir / "s.obj", output, force};
    o.threads = 1;
    o.warn = [](const std::string&) {};
    try {
      rtr::bake(o);
    } catch (const rtr::Error& e) { return e.what(); }
    return "(no error)";
  }
  size_t filesIn(const fs::path& d) { return size_t(std::distance(fs::recursive_directory_iterator(d), {})); }
};

}  // namespace

TEST_F(Fixture, GoodBakeThenExistingOutputNeedsForce) {
  EXPECT_EQ(bakeError(out / "s.rtrscene"), "(no error)");
  EXPECT_TRUE(fs::is_regular_file(out / "s-tex/tex.png"));
  EXPECT_THAT(bakeError(out / "s.rtrscene"), HasSubstr("output exists; use --force"));
  fs::remove(out / "s.rtrscene");
  EXPECT_THAT(bakeError(out / "s.rtrscene"), HasSubstr("s-tex/tex.png: texture exists"));
  EXPECT_FALSE(fs::exists(out / "s.rtrscene"));
  EXPECT_EQ(bakeError(out / "s.rtrscene", true), "(no error)");
}

TEST_F(Fixture, MissingTextureFile) {
  fs::remove(dir / "tex.png");
  EXPECT_THAT(bakeError(out / "s.rtrscene"), HasSubstr("tex.png: texture file named in the MTL does not exist"));
  EXPECT_EQ(filesIn(out), 0u);
}

TEST_F(Fixture, TextureThatIsNotAPng) {
  write("tex.png", "this is text, not a PNG");
  EXPECT_THAT(bakeError(out / "s.comp5892mesh"), HasSubstr("tex.png: cannot decode image"));
  EXPECT_EQ(filesIn(out), 0u);
}

TEST_F(Fixture, MissingMtlIsAWarning) {
  fs::remove(dir / "s.mtl");
  std::vector<std::string> warnings;
  rtr::BakeOptions o{dir / "s.obj", out / "s.rtrscene"};
  o.warn = [&](const std::string& w) { warnings.push_back(w); };
  rtr::bake(o);
  ASSERT_FALSE(warnings.empty());
  EXPECT_THAT(warnings[0], HasSubstr("s.mtl' named by 'mtllib' does not exist"));
  EXPECT_TRUE(fs::is_regular_file(out / "s.rtrscene"));
}

TEST_F(Fixture, MissingOutputFolderIsCreatedAndRemovedAgainIfTheBakeFails) {
  EXPECT_EQ(bakeError(dir / "new/deeper/s.rtrscene"), "(no error)");
  EXPECT_TRUE(fs::is_regular_file(dir / "new/deeper/s.rtrscene"));
  EXPECT_TRUE(fs::is_regular_file(dir / "new/deeper/s-tex/tex.png"));
  fs::remove(dir / "tex.png");
  EXPECT_THAT(bakeError(dir / "other/deeper/s.rtrscene"), HasSubstr("does not exist"));
  EXPECT_FALSE(fs::exists(dir / "other"));
  write("plain", "a file where a folder should be");
  EXPECT_THAT(bakeError(dir / "plain/s.rtrscene"), HasSubstr("cannot create folder"));
}

TEST_F(Fixture, OutputFolderNotWritable) {
  // /proc refuses new files even to root, so this holds whoever runs the test.
  EXPECT_THAT(bakeError("/proc/s.rtrscene"), HasSubstr("/proc"));
  if (::geteuid() != 0) {
    fs::permissions(out, fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_THAT(bakeError(out / "s.rtrscene"), HasSubstr("is not writable"));
    fs::permissions(out, fs::perms::owner_all);
  }
  EXPECT_EQ(filesIn(out), 0u);
}

TEST_F(Fixture, UnknownOutputExtension) { EXPECT_THAT(bakeError(out / "s.glb"), HasSubstr("unknown output format")); }

// Disk full during a --force bake (a file size limit stands in for it: a write past it fails, EFBIG, as
// ENOSPC would): the older scene and its textures stay as they were, and no temporary is left. Before,
// the new textures were already in place when the scene's write failed.
TEST_F(Fixture, FailedForcedBakeKeepsTheOlderOutputWhole) {
  ASSERT_EQ(bakeError(out / "s.rtrscene"), "(no error)");
  auto read = [](const fs::path& f) {
    std::ifstream in(f, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string oldScene = read(out / "s.rtrscene"), oldTexture = read(out / "s-tex/tex.png");
  // The new bake: another texture (9.6 KB) and a scene of a few hundred KB.
  fs::copy_file(rtr::test::sourceDir() / "assets-src/temple/textures/column_col.png", dir / "tex.png",
                fs::copy_options::overwrite_existing);
  std::string obj = "mtllib s.mtl\nusemtl a\n";
  constexpr int kN = 60;
  for (int y = 0; y <= kN; ++y)
    for (int x = 0; x <= kN; ++x) obj += "v " + std::to_string(x) + " " + std::to_string(y) + " 0\nvt 0 0\n";
  for (int y = 0; y < kN; ++y)
    for (int x = 0; x < kN; ++x) {
      const int a = y * (kN + 1) + x + 1, b = a + 1, c = a + kN + 1, d = c + 1;
      obj += "f " + std::to_string(a) + "/" + std::to_string(a) + " " + std::to_string(b) + "/" + std::to_string(b) + " " +
             std::to_string(d) + "/" + std::to_string(d) + " " + std::to_string(c) + "/" + std::to_string(c) + "\n";
    }
  write("s.obj", obj);
  const size_t before = filesIn(out);
  rlimit old{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto oldHandler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit limited = old;
  limited.rlim_cur = 64 << 10;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &limited), 0);
  const std::string err = bakeError(out / "s.rtrscene", true);
  ::setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, oldHandler);
  EXPECT_THAT(err, HasSubstr("s.rtrscene: cannot write: File too large"));
  EXPECT_EQ(read(out / "s.rtrscene"), oldScene);
  EXPECT_EQ(read(out / "s-tex/tex.png"), oldTexture);
  EXPECT_EQ(filesIn(out), before);
  EXPECT_EQ(bakeError(out / "s.rtrscene", true), "(no error)");  // with room, the new one goes in whole
  EXPECT_EQ(read(out / "s-tex/tex.png"), read(dir / "tex.png"));
}
