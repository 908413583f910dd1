#include <cstring>

#include "core/error.hpp"

#include "vk/commands.hpp"
#include "vk/pipeline.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using test::VulkanTest;

// Reads back fill.comp's output and checks every value: out[i] = i * i + offset.
void expectFilled(const vk::Buffer& out, uint32_t count, uint32_t offset) {
  out.invalidate();
  const uint32_t* v = static_cast<const uint32_t*>(out.mapped());
  for (uint32_t i = 0; i < count; ++i) ASSERT_EQ(v[i], i * i + offset) << "at index " << i;
}

TEST_F(VulkanTest, ComputeDispatchWritesEveryValue) {
  constexpr uint32_t kCount = 1000, kOffset = 7;
  vk::Pipeline fill = vk::makeComputePipeline(*ctx, vk::loadShader("fill.comp"));
  vk::Buffer out(*ctx, kCount * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Readback, "fill output");
  std::memset(out.mapped(), 0xFF, kCount * 4);
  out.flush();
  vk::DescriptorSets sets(*ctx, fill.layout, 1);
  vk::DescriptorWriter(*ctx, fill.layout, 0, sets.get(0)).buffer(0, out.handle()).commit();
  struct {
    uint32_t count, offset;
  } push{kCount, kOffset};
  vk::submitAndWait(*ctx, [&](VkCommandBuffer cb) {
    fill.bind(cb);
    fill.bindSet(cb, 0, sets.get(0));
    fill.push(cb, push);
    fill.dispatch(cb, kCount);
    vk::bufferBarrier(cb, vk::kComputeWrite, vk::kHostRead);
  });
  expectFilled(out, kCount, kOffset);
}

TEST_F(VulkanTest, PushDescriptorsBindWithoutAPool) {
  constexpr uint32_t kCount = 300;
  vk::LayoutOptions options;
  options.pushDescriptorSets = {0};
  vk::Pipeline fill = vk::makeComputePipeline(*ctx, vk::loadShader("fill.comp"), options);
  vk::Buffer out(*ctx, kCount * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Readback);
  struct {
    uint32_t count, offset;
  } push{kCount, 3};
  vk::submitAndWait(*ctx, [&](VkCommandBuffer cb) {
    fill.bind(cb);
    vk::DescriptorWriter(*ctx, fill.layout, 0, VK_NULL_HANDLE).buffer(0, out.handle()).push(cb, fill);
    fill.push(cb, push);
    fill.dispatch(cb, kCount);
    vk::bufferBarrier(cb, vk::kComputeWrite, vk::kHostRead);
  });
  expectFilled(out, kCount, 3);
}

TEST_F(VulkanTest, GpuTimerMeasuresAPass) {
  vk::GpuTimer timer(*ctx, 2);
  vk::Pipeline fill = vk::makeComputePipeline(*ctx, vk::loadShader("fill.comp"));
  vk::Buffer out(*ctx, 1 << 20, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Device);
  vk::DescriptorSets sets(*ctx, fill.layout, 1);
  vk::DescriptorWriter(*ctx, fill.layout, 0, sets.get(0)).buffer(0, out.handle()).commit();
  struct {
    uint32_t count, offset;
  } push{1 << 18, 0};
  vk::submitAndWait(*ctx, [&](VkCommandBuffer cb) {
    timer.reset(cb);
    timer.begin(cb);
    fill.bind(cb);
    fill.bindSet(cb, 0, sets.get(0));
    fill.push(cb, push);
    fill.dispatch(cb, 1 << 18);
    timer.mark(cb, "fill");
  });
  auto r = timer.results();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].first, "fill");
  EXPECT_GE(r[0].second, 0.0);
  EXPECT_LT(r[0].second, 10000.0);
}

TEST_F(VulkanTest, WrongPushConstantSizeIsAnError) {
  vk::Pipeline fill = vk::makeComputePipeline(*ctx, vk::loadShader("fill.comp"));
  uint32_t tooSmall = 0;
  vk::submitAndWait(*ctx, [&](VkCommandBuffer cb) { EXPECT_THROW(fill.push(cb, tooSmall), Error); });
}

TEST(VulkanDevices, ChoosingAMissingDeviceNamesTheDevices) {
  vk::ContextOptions o;
  o.device = "no-such-gpu";
  try {
    vk::Context ctx(o);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--device 'no-such-gpu': no Vulkan device matches"), std::string::npos) << e.what();
  }
  o.device = "99";
  EXPECT_THROW(vk::Context{o}, Error);
}

}  // namespace
}  // namespace rtr
