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

class VulkanTest : public ::testing::Test {
 protected:
  void SetUp() override {
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
