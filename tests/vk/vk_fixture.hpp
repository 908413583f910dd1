#pragma once
// Every Vulkan test runs with the validation layer and synchronization validation; any message fails it,
// including leaks reported when the device is destroyed.
#include <memory>

#include <gtest/gtest.h>

#include "vk/context.hpp"

namespace rtr::test {

inline vk::ContextOptions validatedOptions() {
  vk::ContextOptions o = vk::optionsFromEnvironment();
  o.validation = true;
  o.syncValidation = true;
  return o;
}

// Loads the Vulkan driver once for the whole test process, before any layer, and keeps it loaded.
// Why: each test makes and destroys its own instance, and the loader unloads the driver with the last
// instance, while the validation layer stays mapped (its C++ unique symbols make it undeletable) and keeps
// the part of glibc's static TLS surplus it took. The NVIDIA driver's libnvidia-tls.so needs static TLS
// (initial-exec) when it is loaded again, finds the surplus gone, and the instance fails with "cannot
// allocate memory in static TLS block". Loaded first and never unloaded, it takes its TLS once.
inline void pinDriver() {
  static const VkInstance pinned = [] {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.apiVersion = VK_API_VERSION_1_3;
    VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ci.pApplicationInfo = &app;
    VkInstance i = VK_NULL_HANDLE;
    if (vkCreateInstance(&ci, nullptr, &i) != VK_SUCCESS) return VkInstance(VK_NULL_HANDLE);  // the test says why
    uint32_t n = 0;  // the loader opens the drivers' libraries when it lists their devices
    vkEnumeratePhysicalDevices(i, &n, nullptr);
    return i;
  }();
  (void)pinned;
}

class VulkanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    pinDriver();
    vk::Context::resetValidationMessageCount();
    ctx = std::make_unique<vk::Context>(validatedOptions());
  }
  void TearDown() override {
    ctx.reset();
    EXPECT_EQ(vk::Context::validationMessageCount(), 0u) << "validation messages (see stderr)";
  }
  std::unique_ptr<vk::Context> ctx;
};

}  // namespace rtr::test
