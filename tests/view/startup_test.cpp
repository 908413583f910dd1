// rtr-view's start-up as a user meets it: --timings phases that account for the whole time, the defaults
// chosen for the device (and flags that override them), the pipeline and texture caches kept where they are told.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_paths.hpp"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

struct ViewRun {
  int status = -1;
  std::string out;
};

class StartupTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("rtr-startup-" + std::to_string(::getpid()) + "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  // rtr-view on the small temple, headless, with `args`; `env` are env(1)'s words in front (the texture
  // cache is off unless they say otherwise: no run writes into the user's cache folder).
  ViewRun view(const std::string& args, const std::string& env = "") {
    const std::string words = env.find("RTR_TEXTURE_CACHE") == std::string::npos ? env + " RTR_TEXTURE_CACHE=off" : env;
    const std::string cmd = "env " + words + " " + rtr::test::toolPath("rtr-view") + " " +
                            (rtr::test::assetDir() / "temple.rtrscene").string() + " --headless --size 320x180 " +
                            "--screenshot " + (dir / "shot.png").string() + " --force " + args + " 2>&1";
    ViewRun r;
    FILE* pipe = popen(cmd.c_str(), "r");
    char buf[4096];
    while (size_t n = fread(buf, 1, sizeof buf, pipe)) r.out.append(buf, n);
    const int status = pclose(pipe);
    r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
  }
  fs::path dir;
};

// The phases printed by --timings, by name, and the two totals.
std::map<std::string, double> phases(const std::string& out) {
  std::map<std::string, double> p;
  std::istringstream in(out.substr(out.find("start-up phases (ms):")));
  std::string line;
  std::getline(in, line);
  static const std::regex row(R"(^  (\S.*\S) +(-?[0-9]+\.[0-9])$)");
  std::smatch m;
  while (std::getline(in, line) && std::regex_match(line, m, row)) p[m[1]] = std::stod(m[2]);
  return p;
}

TEST_F(StartupTest, TimingsPhasesAddUpToTheTotal) {
  const ViewRun r = view("--timings");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto p = phases(r.out);
  const std::vector<std::string> expected = {"process start to Vulkan (exec, libraries, options)",
                                             "instance and device",
                                             "scene file read",
                                             "texture decode",
                                             "geometry upload",
                                             "texture upload",
                                             "mips",
                                             "renderer setup (start pose, targets)",
                                             "first frame complete (record, GPU, read-back)",
                                             "sum of the phases",
                                             "total from process start"};
  for (const auto& name : expected) EXPECT_TRUE(p.count(name)) << "no phase '" << name << "' in:\n" << r.out;
  double sum = 0;
  int pipelineRows = 0;
  for (const auto& [name, ms] : p) {
    if (name == "sum of the phases" || name == "total from process start") continue;
    EXPECT_GE(ms, 0.0) << name;
    sum += ms;
    pipelineRows += name.rfind("pipeline creation (", 0) == 0;
  }
  EXPECT_EQ(pipelineRows, 1) << r.out;
  const double total = p.at("total from process start");
  EXPECT_GT(total, p.at("instance and device"));
  EXPECT_NEAR(sum, total, 3.0) << "time not in any phase:\n" << r.out;
}

TEST_F(StartupTest, CpuDeviceGetsItsDefaultsAndFlagsOverride) {
  const ViewRun plain = view("");
  ASSERT_EQ(plain.status, 0) << plain.out;
  if (plain.out.find("llvmpipe") == std::string::npos) GTEST_SKIP() << "not on lavapipe: " << plain.out;
  // The documented choice (docs/startup.md), and the frame really took the forward path.
  EXPECT_THAT(plain.out, HasSubstr(": forward shading (default), auto mips (default): the defaults for a CPU device"));
  EXPECT_THAT(plain.out, HasSubstr("  scene: "));
  EXPECT_THAT(plain.out, ::testing::Not(HasSubstr("  shade: ")));

  const ViewRun flags = view("--shading-path visibility --mips compute");
  ASSERT_EQ(flags.status, 0) << flags.out;
  EXPECT_THAT(flags.out, HasSubstr(": visibility shading (--shading-path), compute mips (--mips)\n"));
  EXPECT_THAT(flags.out, ::testing::Not(HasSubstr("the defaults for")));
  EXPECT_THAT(flags.out, HasSubstr("  shade: "));
}

TEST_F(StartupTest, PipelineCacheGoesWhereItIsToldAndNowhereWhenOff) {
  const fs::path cache = dir / "cache";
  ASSERT_EQ(view("", "RTR_PIPELINE_CACHE=" + cache.string()).status, 0);
  ASSERT_TRUE(fs::is_directory(cache));
  int files = 0;
  for (const auto& e : fs::directory_iterator(cache)) files += e.path().filename().string().rfind("pipelines-", 0) == 0;
  EXPECT_EQ(files, 1);

  const fs::path home = dir / "home";
  const ViewRun off = view("--no-pipeline-cache", "-u RTR_PIPELINE_CACHE -u XDG_CACHE_HOME HOME=" + home.string());
  ASSERT_EQ(off.status, 0) << off.out;
  EXPECT_FALSE(fs::exists(home / ".cache/rtr")) << off.out;
  // Without the flag the same run keeps it in the user's cache folder.
  const ViewRun on = view("", "-u RTR_PIPELINE_CACHE -u XDG_CACHE_HOME HOME=" + home.string());
  ASSERT_EQ(on.status, 0) << on.out;
  EXPECT_TRUE(fs::is_directory(home / ".cache/rtr")) << on.out;
}

std::string fileBytes(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

size_t cacheEntries(const fs::path& dir) {
  size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) n += e.path().extension() == ".rtrtex";
  return n;
}

// The texture cache as a user meets it (docs/startup.md): the second open takes every texture from it and
// draws the same image as the first and as one without the cache; --no-cache writes nothing anywhere.
TEST_F(StartupTest, SecondOpenTakesEveryTextureFromTheCacheAndNoCacheWritesNothing) {
  const fs::path cache = dir / "textures";
  const std::string env = "RTR_TEXTURE_CACHE=" + cache.string();
  const ViewRun first = view("--timings", env);
  ASSERT_EQ(first.status, 0) << first.out;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(first.out, m, std::regex(R"(, (\d+) textures;)"))) << first.out;
  const std::string textures = m[1];
  EXPECT_THAT(first.out, HasSubstr("texture cache: 0 hits, " + textures + " misses"));
  EXPECT_THAT(first.out, HasSubstr("  texture cache read-back "));
  EXPECT_EQ(cacheEntries(cache), std::stoul(textures));
  const std::string image = fileBytes(dir / "shot.png");
  const ViewRun second = view("", env);
  ASSERT_EQ(second.status, 0) << second.out;
  EXPECT_THAT(second.out, HasSubstr("texture cache: " + textures + " hits, 0 misses"));
  EXPECT_EQ(fileBytes(dir / "shot.png"), image) << "the cached open drew another image";

  const fs::path home = dir / "home";
  const std::string user = "-u RTR_TEXTURE_CACHE -u RTR_PIPELINE_CACHE -u XDG_CACHE_HOME HOME=" + home.string();
  const ViewRun off = view("--no-cache", user);
  ASSERT_EQ(off.status, 0) << off.out;
  EXPECT_FALSE(fs::exists(home / ".cache/rtr")) << off.out;  // (Mesa keeps its own shader cache beside it)
  EXPECT_EQ(fileBytes(dir / "shot.png"), image) << "the uncached open drew another image";
  const std::string trace = "env " + user + " " + rtr::test::toolPath("rtr-trace") + " " +
                            (rtr::test::assetDir() / "temple.rtrscene").string() + " --size 64x36 --force -o " +
                            (dir / "traced.png").string();
  ASSERT_EQ(std::system((trace + " --no-cache 2>/dev/null").c_str()), 0);
  EXPECT_FALSE(fs::exists(home / ".cache/rtr")) << "rtr-trace --no-cache wrote into the user's cache folder";
  // Without the flag both keep their textures in the user's cache folder.
  ASSERT_EQ(std::system((trace + " 2>/dev/null").c_str()), 0);
  EXPECT_EQ(cacheEntries(home / ".cache/rtr/textures"), std::stoul(textures)) << "rtr-trace stored no chains";
  const ViewRun on = view("", user);
  ASSERT_EQ(on.status, 0) << on.out;
  EXPECT_EQ(cacheEntries(home / ".cache/rtr/textures"), 2 * std::stoul(textures)) << on.out;
}

}  // namespace
