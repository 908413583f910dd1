// The tools as a careless user and concurrent runs meet them: the real executables, driven from here.
// Exit status 2 and a message naming the option for every bad value; no output overwritten without
// --force; output format by extension; concurrent and killed writers never leave a short, mixed or stray file.
// RTR_CLI_BIN_DIR overrides where the executables are (to run these checks against another build).
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/image.hpp"
#include "scene/load.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

namespace {

const fs::path kSource = rtr::test::sourceDir();
const fs::path kCornell = kSource / "assets-src/rt/cornell_box.obj";
const fs::path kTemple = kSource / "assets-src/temple/temple.obj.zst";

fs::path bin(const std::string& tool) {
  const char* dir = std::getenv("RTR_CLI_BIN_DIR");
  return dir ? fs::path(dir) / tool : fs::path(rtr::test::toolPath(tool));
}

std::string readAll(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Result {
  int exitCode = -1;  // -1: killed by a signal or timed out
  std::string out, err;
};

class Process {
 public:
  Process(const std::vector<std::string>& args, const fs::path& logs, int id)
      : outFile_(logs / (std::to_string(id) + ".out")), errFile_(logs / (std::to_string(id) + ".err")) {
    pid_ = ::fork();
    if (pid_ == 0) {
      const int o = ::open(outFile_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int e = ::open(errFile_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(o, 1);
      ::dup2(e, 2);
      std::vector<char*> argv;
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
  }
  void kill(int sig) { ::kill(pid_, sig); }
  // Waits at most `seconds`, then kills it: a hung tool fails the test instead of hanging it.
  Result wait(double seconds = 60) {
    Result r;
    int status = 0;
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (::waitpid(pid_, &status, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() > end) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, &status, 0);
        r.err = "(timed out)";
        return r;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    if (WIFEXITED(status)) r.exitCode = WEXITSTATUS(status);
    r.out = readAll(outFile_);
    r.err += readAll(errFile_);
    return r;
  }

 private:
  fs::path outFile_, errFile_;
  pid_t pid_ = -1;
};

struct Cli : ::testing::Test {
  fs::path dir = fs::temp_directory_path() / ("rtr_cli_" + std::to_string(::getpid()));
  fs::path logs = dir / "logs";
  int ids = 0;
  void SetUp() override {
    fs::remove_all(dir);
    fs::create_directories(logs);
  }
  void TearDown() override { fs::remove_all(dir); }
  Process start(const std::string& tool, std::vector<std::string> args) {
    args.insert(args.begin(), bin(tool).string());
    return Process(args, logs, ids++);
  }
  Result run(const std::string& tool, const std::vector<std::string>& args) { return start(tool, args).wait(); }
  // Everything in `d` but the expected names: stray temporaries show up here.
  std::vector<std::string> namesIn(const fs::path& d) {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(d)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
};

struct BadValue {
  std::string tool;
  std::vector<std::string> args;
  std::string names;  // what the message must name
};

// Every bad value exits 2 with a message naming the option, before any work (rtr-view needs no GPU).
TEST_F(Cli, BadOptionValuesAreUsageErrorsNamingTheOption) {
  const std::string c = kCornell.string(), png = (dir / "x.png").string();
  const std::vector<BadValue> table = {
      {"rtr-view", {c, "--headless", "--screenshot", png, "--size", "4294967297x1"}, "--size"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--size", "0x5"}, "--size"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--size", "16385x4"}, "--size"},  // lavapipe: 16384
      {"rtr-view", {c, "--headless", "--screenshot", png, "--size", "32769x4"}, "--size"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--fov", "0"}, "--fov"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--fov", "nan"}, "--fov"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--fov", "180"}, "--fov"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--fov", "inf"}, "--fov"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--light", "1,2"}, "--light"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--light", "nan,0,0"}, "--light"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--camera", "1,2,3"}, "--camera"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--frames", "0"}, "--frames"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--frames", "4294967297"}, "--frames"},
      {"rtr-view", {c, "--headless", "--bench", "-1"}, "--bench"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--lod-bias", "nan"}, "--lod-bias"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--mips", "fast"}, "--mips"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--mosaic", "on"}, "expected off, compute or graphics"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--filter", "linear"}, "expected trilinear, nearest-mip or nearest"},
      {"rtr-trace", {c, "-o", png, "--shading", "lambert"}, "expected phong, pbr, normals or depth"},
      {"rtr-view", {c, "--headless"}, "--headless"},
      {"rtr-view", {c, "--headless", "--screenshot", (dir / "x.bmp").string()}, "--screenshot"},
      {"rtr-trace", {c, "-o", png, "--size", "4294967297x1"}, "--size"},
      {"rtr-trace", {c, "-o", png, "--size", "64x"}, "--size"},
      {"rtr-trace", {c, "-o", png, "--fov", "nan"}, "--fov"},
      {"rtr-trace", {c, "-o", png, "--fov", "0"}, "--fov"},
      {"rtr-trace", {c, "-o", png, "--fov", "-5"}, "--fov"},
      {"rtr-trace", {c, "-o", png, "--light", "1,2,nan"}, "--light"},
      {"rtr-trace", {c, "-o", png, "--light-color", "a,b,c"}, "--light-color"},
      {"rtr-trace", {c, "-o", png, "--camera", "1,2"}, "--camera"},
      {"rtr-trace", {c, "-o", png, "--bounces", "99999999999999999999"}, "--bounces"},
      {"rtr-trace", {c, "-o", png, "--bounces", "1.5"}, "--bounces"},
      {"rtr-trace", {c, "-o", png, "--threads", "-1"}, "--threads"},
      {"rtr-trace", {c, "-o", png, "--area-samples", "0"}, "--area-samples"},
      {"rtr-trace", {c, "-o", png, "--ambient", "inf"}, "--ambient"},
      {"rtr-trace", {c, "-o", png, "--lod-bias", "nan"}, "--lod-bias"},
      {"rtr-trace", {c, "-o", png, "--ortho-height", "0"}, "--ortho-height"},
      {"rtr-trace", {c, "-o", (dir / "x.bmp").string()}, ".bmp"},
      {"rtr-trace", {c}, "--output"},
      {"rtr-bake", {c, (dir / "x.rtrscene").string(), "--threads", "-1"}, "--threads"},
      {"rtr-bake", {c, (dir / "x.rtrscene").string(), "--threads", "4294967297"}, "--threads"},
      {"rtr-bake", {c, (dir / "x.rtrscene").string(), "--view", "1,2"}, "--view"},
      {"rtr-bake", {c, (dir / "x.glb").string()}, "unknown output format"},
      {"rtr-bake", {c, (dir / "x.rtrscene").string(), "--light", "1,2"}, "--light"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--ambient", "0.1,nan,0"}, "--ambient"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--light-color", "1,1"}, "--light-color"},
      {"rtr-trace", {c, "-o", png, "--ambient", "0.5,0.5"}, "--ambient"},
      // Issue 33: empty values, blanks on either side, negative colours, a colour without its light, a
      // device that matches nothing, an output folder that is a file.
      {"rtr-bake", {c, (dir / "x.rtrscene").string(), "--light-color", "nan"}, "--light-color"},
      {"rtr-bake", {c, (dir / "x.rtrscene").string(), "--light-color", "1,1,1"}, "--light"},
      {"rtr-bake", {c, (dir / "x.rtrscene").string(), "--light", "0,1,0", "--light-color", "1e40,1,1"}, "--light-color"},
      {"rtr-bake", {c, (dir / "x.rtrscene").string(), "--light", "0,1,0", "--light-color", ""}, "--light-color"},
      {"rtr-bake", {c, (dir / "x.rtrscene").string(), "--light", "0,1,0", "--light-color", "-1,1,1"}, "--light-color"},
      {"rtr-bake", {c, (dir / "x.rtrscene").string(), "--light", ""}, "--light"},
      {"rtr-bake", {c, (dir / "x.rtrscene").string(), "--view", ""}, "--view"},
      {"rtr-bake", {c, (dir / "x.rtrscene").string(), "--textures", "png"}, "--textures"},
      {"rtr-bake", {c, (dir / "x.comp5892mesh").string(), "--textures", "bc"}, "--textures files"},
      {"rtr-trace", {c, "-o", png, "--light", "0,1,0", "--light-color", ""}, "--light-color"},
      {"rtr-trace", {c, "-o", png, "--light", "0,1,0", "--light-color", "-1,0,0"}, "--light-color"},
      {"rtr-trace", {c, "-o", png, "--ambient", "-0.5"}, "--ambient"},
      {"rtr-trace", {c, "-o", png, "--ambient", ""}, "--ambient"},
      {"rtr-trace", {c, "-o", png, "--fov", " 5"}, "--fov"},
      {"rtr-trace", {c, "-o", png, "--fov", "5 "}, "--fov"},
      {"rtr-trace", {c, "-o", png, "--fov", ""}, "--fov"},
      {"rtr-trace", {c, "-o", png, "--size", ""}, "--size"},
      {"rtr-trace", {c, "-o", png, "--camera", ""}, "--camera"},
      {"rtr-trace", {c, "-o", c + "/x.png"}, "is not a folder"},
      {"rtr-trace", {c, "-o", png, "--spp", "0"}, "--spp"},
      {"rtr-trace", {c, "-o", png, "--env-intensity", "-1"}, "--env-intensity"},
      {"rtr-trace", {c, "-o", png, "--env-intensity", "nan"}, "--env-intensity"},
      {"rtr-trace", {c, "-o", png, "--env-rotation", "inf"}, "--env-rotation"},
      {"rtr-trace", {c, "-o", png, "--background", "1,-1,0"}, "--background"},
      {"rtr-trace", {c, "-o", png, "--background", ""}, "--background"},
      {"rtr-trace", {c, "-o", png, "--env", "sky.png"}, "--env"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--ambient", "0,-1,0"}, "--ambient"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--light-color", "1,1,1"}, "--light"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--mode", " 5"}, "--mode"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--device", "no-such-device"}, "--device"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--background", "0.5,nan,0"}, "--background"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--background", "-1"}, "--background"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--env-intensity", "-1"}, "--env-intensity"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--env-rotation", "inf"}, "--env-rotation"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--env-blur", "2"}, "--env-blur"},
      {"rtr-view", {c, "--headless", "--screenshot", png, "--brdf", "phong"}, "expected beckmann or ggx"},
      {"scenegen", {"--scale", "nan"}, "--scale"},
      {"scenegen", {"--scale", "1e9"}, "--scale"},
      {"scenegen", {"--textures", "abc"}, "--textures"},
  };
  for (const BadValue& row : table) {
    std::string line = row.tool;
    for (const auto& a : row.args) line += " " + a;
    const Result r = run(row.tool, row.args);
    EXPECT_EQ(r.exitCode, 2) << line << "\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr(row.names)) << line;
  }
  EXPECT_FALSE(fs::exists(dir / "x.png"));
  EXPECT_FALSE(fs::exists(dir / "x.rtrscene"));
}

// --env none is the image without the option, byte for byte; an environment changes it; a missing
// environment file is a failure naming it (exit 1), and no image is written.
TEST_F(Cli, EnvironmentOptions) {
  const std::string c = kCornell.string(), a = (dir / "a.png").string(), b = (dir / "b.png").string(),
                    e = (dir / "e.png").string();
  const std::vector<std::string> common = {c, "--headless", "--size", "48x32", "--validation"};
  auto with = [&](std::vector<std::string> extra) {
    extra.insert(extra.begin(), common.begin(), common.end());
    return extra;
  };
  Result r = run("rtr-view", with({"-o", a}));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  r = run("rtr-view", with({"-o", b, "--env", "none"}));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(readAll(a), readAll(b));
  r = run("rtr-view", with({"-o", e, "--env", "sky", "--env-rotation", "30"}));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("environment sky prefiltered"));
  EXPECT_THAT(r.err, Not(HasSubstr("[vulkan ")));
  EXPECT_NE(readAll(a), readAll(e));
  const std::string missing = (dir / "no-such.hdr").string();
  r = run("rtr-view", with({"-o", (dir / "m.png").string(), "--env", missing}));
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr(missing));
  EXPECT_FALSE(fs::exists(dir / "m.png"));
}

TEST_F(Cli, VersionAndExitStatusInHelp) {
  for (const std::string tool : {"rtr-view", "rtr-trace", "rtr-bake", "rtr-reflect"}) {
    const Result v = run(tool, {"--version"});
    EXPECT_EQ(v.exitCode, 0) << tool << v.err;
    EXPECT_THAT(v.out, HasSubstr(tool + " 0.")) << tool;
    EXPECT_THAT(v.out, HasSubstr("git ")) << tool;
    const Result h = run(tool, {"--help"});
    EXPECT_EQ(h.exitCode, 0) << tool;
    EXPECT_THAT(h.out, HasSubstr("2 usage error")) << tool;
  }
}

TEST_F(Cli, NoToolOverwritesWithoutForce) {
  const fs::path shot = dir / "shot.png", traced = dir / "t.png", baked = dir / "b.rtrscene";
  for (const fs::path& f : {shot, traced, baked}) std::ofstream(f) << "keep me";
  const std::vector<std::pair<std::string, std::vector<std::string>>> runs = {
      {"rtr-view", {kCornell.string(), "--headless", "--screenshot", shot.string()}},
      {"rtr-trace", {kCornell.string(), "-o", traced.string(), "--size", "16x16", "-q"}},
      {"rtr-bake", {kCornell.string(), baked.string()}},
  };
  for (const auto& [tool, args] : runs) {
    const Result r = run(tool, args);
    EXPECT_EQ(r.exitCode, 2) << tool << "\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr("--force")) << tool;
  }
  for (const fs::path& f : {shot, traced, baked}) EXPECT_TRUE(readAll(f) == "keep me") << f << " was overwritten";
  // With --force they do overwrite (rtr-view only up to needing a GPU, so not run here).
  EXPECT_EQ(run("rtr-trace", {kCornell.string(), "-o", traced.string(), "--size", "16x16", "-q", "--force"}).exitCode, 0);
  EXPECT_EQ(run("rtr-bake", {kCornell.string(), baked.string(), "--force"}).exitCode, 0);
  EXPECT_EQ(rtr::loadImage(traced, 4).width, 16u);
  EXPECT_NO_THROW(rtr::loadScene(baked));
}

TEST_F(Cli, TraceOutputFormatFollowsTheExtension) {
  const std::string c = kCornell.string();
  for (const char* name : {"a.jpg", "a.exr", "a.hdr", "a.png"})
    ASSERT_EQ(run("rtr-trace", {c, "-o", (dir / name).string(), "--size", "24x16", "-q"}).exitCode, 0) << name;
  EXPECT_EQ(readAll(dir / "a.jpg").substr(0, 2), "\xFF\xD8");
  EXPECT_EQ(readAll(dir / "a.exr").substr(0, 4), "\x76\x2F\x31\x01");
  EXPECT_EQ(readAll(dir / "a.hdr").substr(0, 10), "#?RADIANCE");
  EXPECT_EQ(readAll(dir / "a.png").substr(1, 3), "PNG");
  const Result r = run("rtr-trace", {c, "-o", (dir / "a.tiff").string(), "--size", "24x16", "-q"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_THAT(r.err, HasSubstr(".png, .jpg"));
}

// N writers of one output at once, all with --force: each succeeds and the file is one of theirs, whole.
TEST_F(Cli, ConcurrentBakesAndImageWritesLeaveOneCompleteFile) {
  const fs::path out = dir / "out" / "t.rtrscene";
  const fs::path ref = dir / "ref" / "t.rtrscene";
  fs::create_directories(out.parent_path());
  fs::create_directories(ref.parent_path());
  ASSERT_EQ(run("rtr-bake", {kTemple.string(), ref.string()}).exitCode, 0);
  const fs::path png = dir / "t.png", refPng = dir / "ref.png";
  const std::vector<std::string> trace = {kCornell.string(), "--size", "96x64", "-q", "--threads", "1", "--force", "-o"};
  auto traceTo = [&](const fs::path& f) {
    auto a = trace;
    a.push_back(f.string());
    return a;
  };
  ASSERT_EQ(run("rtr-trace", traceTo(refPng)).exitCode, 0);
  for (int n : {2, 8}) {
    std::vector<Process> ps;
    for (int i = 0; i < n; ++i) {
      ps.push_back(start("rtr-bake", {kTemple.string(), out.string(), "--force", "--threads", "1"}));
      ps.push_back(start("rtr-trace", traceTo(png)));
    }
    for (auto& p : ps) {
      const Result r = p.wait(120);
      EXPECT_EQ(r.exitCode, 0) << r.err;
    }
    EXPECT_TRUE(readAll(out) == readAll(ref)) << n << " concurrent bakes";
    EXPECT_NO_THROW(rtr::loadScene(out));
    EXPECT_TRUE(rtr::loadImage(png, 4).texels == rtr::loadImage(refPng, 4).texels) << n << " concurrent traces";
    EXPECT_EQ(namesIn(out.parent_path()), (std::vector<std::string>{"t-tex", "t.rtrscene"}));
    EXPECT_EQ(namesIn(dir), (std::vector<std::string>{"logs", "out", "ref", "ref.png", "t.png"}));
  }
}

// SIGKILL at random points of a bake: the output is always the old file or the new one, whole; the next
// run leaves no temporary behind.
TEST_F(Cli, KilledBakeLeavesTheOldFileAndTheNextRunNoTemporary) {
  const fs::path out = dir / "out" / "t.rtrscene";
  fs::create_directories(out.parent_path());
  const std::vector<std::string> a = {kTemple.string(), out.string(), "--force", "--view", "1,2,3,4,5"};
  const std::vector<std::string> b = {kTemple.string(), out.string(), "--force", "--view", "5,4,3,2,1"};
  ASSERT_EQ(run("rtr-bake", b).exitCode, 0);
  const std::string newBytes = readAll(out);
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(run("rtr-bake", a).exitCode, 0);
  const double bakeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string oldBytes = readAll(out);
  ASSERT_TRUE(oldBytes != newBytes);
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> when(0.0, bakeSeconds * 1.2);
  // A file other than the output and its texture folder: a temporary being written.
  auto writing = [&] {
    std::error_code ec;
    for (const fs::path& d : {out.parent_path(), out.parent_path() / "t-tex"})
      for (auto it = fs::directory_iterator(d, ec); !ec && it != fs::directory_iterator(); it.increment(ec))
        if (it->path().filename().string().find("tmp") != std::string::npos) return true;
    return false;
  };
  int killed = 0, killedWriting = 0;
  for (int i = 0; i < 12; ++i) {
    Process p = start("rtr-bake", b);
    if (i % 2) {
      std::this_thread::sleep_for(std::chrono::duration<double>(when(rng)));
    } else {  // the moment a temporary exists, so that some kills surely land mid-write
      const auto giveUp = std::chrono::steady_clock::now() + std::chrono::seconds(5);
      while (!writing() && std::chrono::steady_clock::now() < giveUp) {}
      killedWriting += writing();
    }
    p.kill(SIGKILL);
    const Result r = p.wait(30);
    killed += r.exitCode == -1;
    const std::string now = readAll(out);
    EXPECT_TRUE(now == oldBytes || now == newBytes) << "a killed bake left " << now.size() << " bytes";
    if (now == newBytes) std::ofstream(out, std::ios::binary) << oldBytes;  // start again from the old file
  }
  EXPECT_GT(killed, 0);
  EXPECT_GT(killedWriting, 0);
  ASSERT_EQ(run("rtr-bake", b).exitCode, 0);
  EXPECT_TRUE(readAll(out) == newBytes);
  EXPECT_EQ(namesIn(out.parent_path()), (std::vector<std::string>{"t-tex", "t.rtrscene"}));
  for (const auto& e : fs::directory_iterator(out.parent_path() / "t-tex"))
    EXPECT_EQ(e.path().filename().string().find(".rtrtmp"), std::string::npos) << e.path();
}

// A scene without lights is never black in silence: both tools say they add a headlight, and with
// --no-default-light an all-black image gets a warning (exit 0: the image is what was asked for).
TEST_F(Cli, NoLightsIsNeverBlackInSilence) {
  const fs::path obj = dir / "sheet.obj";
  std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";  // no MTL, no light
  const std::string png = (dir / "t.png").string(), vpng = (dir / "v.png").string();
  Result r = run("rtr-trace", {obj.string(), "-o", png, "--size", "32x24"});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("headlight"));
  EXPECT_THAT(r.err, Not(HasSubstr("no lit pixel")));
  // The ambient alone would light it a little: without ambient it is black.
  r = run("rtr-trace", {obj.string(), "-o", png, "--size", "32x24", "--force", "--no-default-light", "--ambient", "0"});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("warning: the image has no lit pixel: the scene has no lights"));
  r = run("rtr-view",
          {obj.string(), "--headless", "--screenshot", vpng, "--size", "32x24", "--no-default-light", "--ambient", "0"});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("warning: the image has no lit pixel: the scene has no lights"));
  r = run("rtr-view", {obj.string(), "--headless", "--screenshot", vpng, "--size", "32x24", "--force"});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("headlight"));
  EXPECT_THAT(r.err, Not(HasSubstr("warning")));
  // A camera that looks away: the scene is outside the view, said in both tools.
  r = run("rtr-trace", {obj.string(), "-o", png, "--size", "32x24", "--force", "--camera", "0.3,0.3,3,180,0"});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("warning: the scene lies wholly outside the view"));
  r = run("rtr-view", {obj.string(), "--headless", "-o", vpng, "--size", "32x24", "--force", "--camera", "0.3,0.3,3,180,0"});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("warning: the scene lies wholly outside the view"));
}

}  // namespace
