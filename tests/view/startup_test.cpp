// rtr-view's start-up as a user meets it: --timings phases that account for the whole time, the defaults
// chosen for the device (and flags that override them), the pipeline and texture caches kept where they are told.
#include <unistd.h>

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
  ViewRun view(const std::string& args, const std::string& env = "",
               const fs::path& scene = rtr::test::assetDir() / "temple.rtrscene") {
    const std::string words = env.find("RTR_TEXTURE_CACHE") == std::string::npos ? env + " RTR_TEXTURE_CACHE=off" : env;
    ViewRun r;
    r.out = rtr::test::runTool(
        "rtr-view",
        scene.string() + " --headless --size 320x180 --screenshot " + (dir / "shot.png").string() + " --force " + args, &r.status,
        words);
    r.status = rtr::test::exitCode(r.status);
    return r;
  }
  fs::path dir;
};

std::string fileBytes(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

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

// The critical path's rows tile the time; the scene file read, made on its own thread while the instance
// and device are, the pipelines, made on theirs while the scene uploads, and the textures, decoded on theirs
// while the geometry uploads, have rows of their own marked beside, each not in the sum.
TEST_F(StartupTest, TimingsCriticalPathAddsUpToTheTotalAndTheReadAndPipelinesRunBeside) {
  const ViewRun r = view("--timings");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto p = phases(r.out);
  const std::string read = "scene file read (beside instance and device)";
  std::string ahead;   // "pipelines made ahead (N, H from the cache) (beside the scene upload)"
  std::string upload;  // "geometry upload (S MB, R GB/s, PATH)"
  for (const auto& [name, ms] : p) {
    if (name.rfind("pipelines made ahead (", 0) == 0 && name.find(") (beside the scene upload)") != std::string::npos)
      ahead = name;
    if (name.rfind("geometry upload (", 0) == 0) upload = name;
  }
  ASSERT_FALSE(upload.empty()) << "no geometry upload row:\n" << r.out;
  ASSERT_FALSE(ahead.empty()) << "no row of the pipelines made beside the upload:\n" << r.out;
  EXPECT_EQ(ahead.find("pipelines made ahead (0,"), std::string::npos) << r.out;
  const std::vector<std::string> expected = {"process start to Vulkan (exec, libraries, options)",
                                             "instance and device",
                                             "waiting for the scene file read",
                                             read,
                                             "settings, the pipelines' thread started",
                                             "texture decode",
                                             "textures decoded (beside the geometry upload)",
                                             "texture upload",
                                             "mips",
                                             "waiting for the pipelines",
                                             "renderer setup (start pose, targets)",
                                             "first frame complete (record, GPU, read-back)",
                                             "sum of the critical path's phases",
                                             "total from process start"};
  for (const auto& name : expected) EXPECT_TRUE(p.count(name)) << "no phase '" << name << "' in:\n" << r.out;
  // The upload's row names its size, rate and path: lavapipe's default is direct.
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(\n  geometry upload \([0-9.]+ MB, [0-9.]+ GB/s, direct\) )"))) << r.out;
  double sum = 0;
  int pipelineRows = 0, besideRows = 0;
  for (const auto& [name, ms] : p) {
    if (name == "sum of the critical path's phases" || name == "total from process start") continue;
    EXPECT_GE(ms, 0.0) << name;
    if (name.find(" (beside ") != std::string::npos) {
      ++besideRows;
      continue;
    }
    sum += ms;
    pipelineRows += name.rfind("pipeline creation (", 0) == 0;
  }
  EXPECT_EQ(pipelineRows, 1) << r.out;
  EXPECT_EQ(besideRows, 3) << r.out;
  // The temple's textures are decoded beside the geometry upload (GpuScene, TextureLoad::Wait).
  EXPECT_GT(p.at("textures decoded (beside the geometry upload)"), 0.0) << r.out;
  const double total = p.at("total from process start");
  EXPECT_GT(total, p.at("instance and device"));
  EXPECT_NEAR(sum, total, 3.0) << "time not in any phase, or a phase counted twice:\n" << r.out;
  EXPECT_NEAR(p.at("sum of the critical path's phases"), sum, 0.5) << r.out;
  // The read starts with the device's start and is waited for: it lies within those two rows.
  EXPECT_LE(p.at(read), p.at("instance and device") + p.at("waiting for the scene file read") + 1.0) << r.out;
  // The pipelines start with the upload and are waited for after it.
  EXPECT_LE(p.at(ahead), p.at("settings, the pipelines' thread started") + p.at("texture decode") + p.at(upload) +
                             p.at("texture upload") + p.at("mips") + p.at("waiting for the pipelines") + 1.0)
      << r.out;
}

// A pipeline that cannot be made beside the upload is reported once the upload is done, with exit 1 (here:
// a measuring variant asked for by a value the rasteriser does not know), and nothing crashes.
TEST_F(StartupTest, APipelineFailureBesideTheUploadIsReported) {
  const ViewRun r = view("--validation --shading-path visibility --raster compute", "RTR_RASTER_MEASURE=bogus RTR_VALIDATION=1");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_THAT(r.out, HasSubstr("rtr-view: error: ")) << r.out;
  EXPECT_THAT(r.out, HasSubstr("RTR_RASTER_MEASURE=bogus: expected no-atomics or setup")) << r.out;
  EXPECT_THAT(r.out, ::testing::Not(HasSubstr("alidation"))) << r.out;
}

// A bad scene file and a device that cannot start: the file's error is the one reported (exit 1), the
// device's in a note before it; a bad file beside a good device ends cleanly (no crash, no validation
// message); a good file beside a missing device reports the device (exit 2, a usage error).
TEST_F(StartupTest, ABadSceneIsReportedWhateverTheDeviceDoes) {
  const fs::path bad = dir / "bad.rtrscene";
  {
    const std::string bytes = fileBytes(rtr::test::assetDir() / "temple.rtrscene");
    std::ofstream(bad, std::ios::binary).write(bytes.data(), 5000);
  }
  const std::string fileError = "rtr-view: error: " + bad.string() + ": byte ";
  const ViewRun badFile = view("--validation", "RTR_VALIDATION=1", bad);
  EXPECT_EQ(badFile.status, 1) << badFile.out;
  EXPECT_THAT(badFile.out, HasSubstr(fileError)) << badFile.out;
  EXPECT_THAT(badFile.out, ::testing::Not(HasSubstr("note: the device's start failed"))) << badFile.out;
  EXPECT_THAT(badFile.out, ::testing::Not(HasSubstr("alidation"))) << badFile.out;

  const ViewRun both = view("--device no-such-device", "", bad);
  EXPECT_EQ(both.status, 1) << both.out;
  const size_t note = both.out.find(
      "rtr-view: note: the device's start failed too (the scene's error below): --device "
      "'no-such-device': no Vulkan device matches");
  const size_t error = both.out.find(fileError);
  ASSERT_NE(note, std::string::npos) << both.out;
  ASSERT_NE(error, std::string::npos) << both.out;
  EXPECT_LT(note, error) << both.out;
  EXPECT_EQ(both.out.find("rtr-view: error: --device"), std::string::npos) << both.out;

  const ViewRun noDevice = view("--device no-such-device");
  EXPECT_EQ(noDevice.status, 2) << noDevice.out;
  EXPECT_THAT(noDevice.out, HasSubstr("rtr-view: error: --device 'no-such-device': no Vulkan device matches"));
  EXPECT_THAT(noDevice.out, ::testing::Not(HasSubstr("note: the device's start failed")));
}

TEST_F(StartupTest, CpuDeviceGetsItsDefaultsAndFlagsOverride) {
  const ViewRun plain = view("");
  ASSERT_EQ(plain.status, 0) << plain.out;
  if (plain.out.find("llvmpipe") == std::string::npos) GTEST_SKIP() << "not on lavapipe: " << plain.out;
  // The documented choice (docs/startup.md), and the frame really took the forward path.
  EXPECT_THAT(plain.out, HasSubstr(": forward shading (default), auto mips (default), near-plane crossings to the hardware "
                                   "(default): the defaults for a CPU device"));
  EXPECT_THAT(plain.out, HasSubstr("  scene: "));
  EXPECT_THAT(plain.out, ::testing::Not(HasSubstr("  shade: ")));

  const ViewRun flags = view("--shading-path visibility --mips compute --raster compute --near-clip compute");
  ASSERT_EQ(flags.status, 0) << flags.out;
  EXPECT_THAT(flags.out, HasSubstr(": visibility shading (--shading-path), compute mips (--mips), near-plane crossings "
                                   "clipped in compute (--near-clip)\n"));
  EXPECT_THAT(flags.out, ::testing::Not(HasSubstr("the defaults for")));
  EXPECT_THAT(flags.out, HasSubstr("  shade: "));
  EXPECT_THAT(flags.out, HasSubstr("  raster clip: "));  // the compute clipping pass ran
  // lavapipe's default hands the crossings to the hardware: no clipping pass in the frame.
  const ViewRun computeRaster = view("--shading-path visibility --raster compute");
  ASSERT_EQ(computeRaster.status, 0) << computeRaster.out;
  EXPECT_THAT(computeRaster.out, HasSubstr("  raster hw: "));
  EXPECT_THAT(computeRaster.out, ::testing::Not(HasSubstr("  raster clip: ")));
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
