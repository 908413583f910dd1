// The pipeline cache on disk: a second start finds every pipeline in it; a damaged, short or foreign
// file is ignored with a note (never handed to the driver) and replaced by a good one.
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <iterator>

#include <gmock/gmock.h>

#include "vk/pipeline.hpp"
#include "vk/pipeline_cache.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

namespace fs = std::filesystem;

class PipelineCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    test::pinDriver();
    vk::Context::resetValidationMessageCount();
    dir = fs::temp_directory_path() /
          ("rtr-pcache-" + std::to_string(::getpid()) + "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
  }
  void TearDown() override {
    fs::remove_all(dir);
    EXPECT_EQ(vk::Context::validationMessageCount(), 0u) << "validation messages (see stderr)";
  }
  // One start: a context on `dir`, the mip generator's two pipelines made in parallel through the one
  // cache; returns its counts (and the cache file).
  vk::PipelineStats start(bool* loaded = nullptr) {
    vk::ContextOptions o = test::validatedOptions();
    o.pipelineCacheDir = dir;
    vk::Context ctx(o);
    const auto make = [&](const char* shader) {
      return [&ctx, shader] { vk::makeComputePipeline(ctx, vk::loadShader(shader), {.pushDescriptorSets = {0}}); };
    };
    vk::inParallel({make("mips_even.comp"), make("mips.comp")});
    file = ctx.pipelineCache().file();
    if (loaded) *loaded = ctx.pipelineCache().loaded();
    return ctx.pipelineCache().stats();
  }  // the context's end saves the cache
  std::string bytes() {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  void write(const std::string& b) { std::ofstream(file, std::ios::binary | std::ios::trunc) << b; }
  // A start with the file as it is now: ignored with a note naming `why`, every pipeline still made,
  // and a good cache written for the start after it.
  void expectIgnored(const std::string& why) {
    ::testing::internal::CaptureStderr();
    bool loaded = true;
    const vk::PipelineStats s = start(&loaded);
    const std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_FALSE(loaded);
    EXPECT_THAT(err, ::testing::HasSubstr("ignored (" + why));
    EXPECT_EQ(s.created, 2u);
    EXPECT_EQ(s.cacheHits, 0u);
    start(&loaded);
    EXPECT_TRUE(loaded) << "the ignored file was not replaced by a good one";
  }

  fs::path dir, file;
};

TEST_F(PipelineCacheTest, SecondStartCreatesNothingFromScratch) {
  bool loaded = true;
  const vk::PipelineStats cold = start(&loaded);
  EXPECT_FALSE(loaded);
  EXPECT_EQ(cold.created, 2u);
  EXPECT_EQ(cold.cacheHits, 0u);
  ASSERT_TRUE(fs::exists(file)) << file;
  EXPECT_EQ(file.parent_path(), dir);

  // Our 56-byte header and the driver's 32: a driver that keeps nothing else (lavapipe JIT-compiles
  // at draw time and stores no code) cannot hit; the GPU drivers do (docs/startup.md).
  if (bytes().size() <= 56 + 32) GTEST_SKIP() << "the driver stores nothing in its pipeline cache";
  const vk::PipelineStats warm = start(&loaded);
  EXPECT_TRUE(loaded);
  EXPECT_EQ(warm.created, 2u);
  // The driver says whether each pipeline came from the cache; this one must say so for the test to mean it.
  ASSERT_EQ(warm.reported, warm.created) << "the driver gives no creation feedback: hits cannot be counted";
  EXPECT_EQ(warm.cacheHits, warm.created);
}

TEST_F(PipelineCacheTest, GarbageFileIsIgnored) {
  start();
  write(std::string(4096, '\x5a'));
  expectIgnored("not an rtr pipeline cache");
}

TEST_F(PipelineCacheTest, TruncatedFileIsIgnored) {
  start();
  const std::string b = bytes();
  ASSERT_GE(b.size(), 56u + 32u);
  write(b.substr(0, b.size() - 7));
  expectIgnored("truncated");
  write(b.substr(0, 20));
  expectIgnored("shorter than its header");
}

TEST_F(PipelineCacheTest, DamagedOrForeignFileIsIgnored) {
  start();
  std::string b = bytes();
  b[b.size() - 3] ^= 0x40;  // one bit of the driver's data
  write(b);
  expectIgnored("checksum mismatch");
  b = bytes();
  b[24] ^= 0x01;  // the first byte of the device UUID in our header
  write(b);
  expectIgnored("made by another device or driver");
}

// Pipelines made on parallel threads count their wall time once: the creation time is never more than
// the time the parallel call took (summed per pipeline, it was about twice that on lavapipe's two cores).
TEST_F(PipelineCacheTest, ParallelCreationIsTimedOnce) {
  vk::ContextOptions o = test::validatedOptions();
  o.pipelineCacheDir.clear();
  vk::Context ctx(o);
  std::vector<std::function<void()>> jobs;
  for (const char* shader : {"mips_even.comp", "mips.comp", "mips_even.comp", "mips.comp"})
    jobs.push_back([&ctx, shader] { vk::makeComputePipeline(ctx, vk::loadShader(shader), {.pushDescriptorSets = {0}}); });
  const auto t = std::chrono::steady_clock::now();
  vk::inParallel(jobs);
  const double wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
  const vk::PipelineStats s = ctx.pipelineCache().stats();
  EXPECT_EQ(s.created, 4u);
  EXPECT_GT(s.ms, 0.0);
  EXPECT_LE(s.ms, wallMs);
}

}  // namespace
}  // namespace rtr
