#pragma once
#include <string>

#include <vulkan/vulkan.h>

#include "core/error.hpp"

namespace rtr::vk {

const char* resultName(VkResult r);

// Every Vulkan call that can fail goes through this: a failure becomes an rtr::Error naming the call.
#define VK_CHECK(call)                                                                                                        \
  do {                                                                                                                        \
    VkResult vk_check_result_ = (call);                                                                                       \
    if (vk_check_result_ < 0) throw ::rtr::Error(std::string(#call) + " failed: " + ::rtr::vk::resultName(vk_check_result_)); \
  } while (0)

}  // namespace rtr::vk
