#include "vk/context.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <vk_mem_alloc.h>

#include "vk/check.hpp"
#include "vk/pipeline_cache.hpp"
#include "vk/pipeline_executables.hpp"

namespace rtr::vk {
namespace {

// llvmpipe's vkCreateDevice crashes (SIGSEGV inside the driver) when the address space runs out while it
// starts its threads and LLVM: under `ulimit -v` 800 MB on the 2-core development VM, fine at 850 MB. A
// CPU device is therefore refused up front below 1 GB, with the reason, instead of crashing.
constexpr uint64_t kCpuDeviceAddressSpace = uint64_t(1) << 30;

void checkCpuDeviceAddressSpace(const VkPhysicalDeviceProperties& p) {
  rlimit r{};
  if (p.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU || ::getrlimit(RLIMIT_AS, &r) != 0 || r.rlim_cur == RLIM_INFINITY ||
      r.rlim_cur >= kCpuDeviceAddressSpace)
    return;
  throw Error(std::string("out of memory: ") + p.deviceName + " (a CPU device) needs about " +
              std::to_string(kCpuDeviceAddressSpace >> 20) + " MB of address space to start; ulimit -v allows " +
              std::to_string(uint64_t(r.rlim_cur) >> 20) + " MB");
}

std::atomic<uint32_t> g_validationMessages{0};

VKAPI_ATTR VkBool32 VKAPI_CALL onValidationMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
    ++g_validationMessages;
    std::fprintf(stderr, "[vulkan %s] %s\n", severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning",
                 data->pMessage);
  }
  return VK_FALSE;
}

VkDebugUtilsMessengerCreateInfoEXT messengerInfo() {
  VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = onValidationMessage;
  return info;
}

bool hasLayer(const char* name) {
  uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  return std::any_of(layers.begin(), layers.end(), [&](auto& l) { return std::strcmp(l.layerName, name) == 0; });
}

int typeRank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
  uint32_t n = 0;
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &n, nullptr));
  std::vector<VkPhysicalDevice> devices(n);
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &n, devices.data()));
  return devices;
}

VkPhysicalDevice choosePhysicalDevice(VkInstance instance, const std::string& want) {
  auto devices = physicalDevices(instance);
  if (devices.empty()) throw Error("no Vulkan device found (is mesa-vulkan-drivers installed? run tools/setup.sh)");
  auto name = [](VkPhysicalDevice d) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    return std::string(p.deviceName);
  };
  if (!want.empty()) {
    char* end = nullptr;
    unsigned long index = std::strtoul(want.c_str(), &end, 10);
    if (*end == '\0') {
      if (index >= devices.size())
        throw UsageError("--device " + want + ": index out of range: " + std::to_string(devices.size()) + " device(s)");
      return devices[index];
    }
    for (auto d : devices)
      if (name(d).find(want) != std::string::npos) return d;
    std::string all;
    for (auto d : devices) all += "\n  " + name(d);
    throw UsageError("--device '" + want + "': no Vulkan device matches; devices:" + all);
  }
  return *std::min_element(devices.begin(), devices.end(), [](VkPhysicalDevice a, VkPhysicalDevice b) {
    VkPhysicalDeviceProperties pa, pb;
    vkGetPhysicalDeviceProperties(a, &pa);
    vkGetPhysicalDeviceProperties(b, &pb);
    return typeRank(pa.deviceType) < typeRank(pb.deviceType);
  });
}

}  // namespace

ContextOptions optionsFromEnvironment() {
  ContextOptions o;
#ifndef NDEBUG
  o.validation = true;
#endif
  if (const char* v = std::getenv("RTR_VALIDATION")) o.validation = o.syncValidation = std::strcmp(v, "0") != 0;
  if (const char* d = std::getenv("RTR_DEVICE")) o.device = d;
  if (const char* c = std::getenv("RTR_PIPELINE_CACHE")) {
    if (std::strcmp(c, "0") != 0 && std::strcmp(c, "off") != 0) o.pipelineCacheDir = c;
  } else {
    o.pipelineCacheDir = defaultPipelineCacheDir();
  }
  return o;
}

uint32_t Context::validationMessageCount() { return g_validationMessages.load(); }
void Context::resetValidationMessageCount() { g_validationMessages = 0; }

Context::Context(const ContextOptions& options) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "rtr";
  app.apiVersion = VK_API_VERSION_1_3;

  std::vector<const char*> extensions = options.instanceExtensions;
  std::vector<const char*> layers;
  VkDebugUtilsMessengerCreateInfoEXT debugInfo = messengerInfo();
  VkValidationFeatureEnableEXT syncFeature = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  if (options.validation) {
    if (!hasLayer("VK_LAYER_KHRONOS_validation"))
      throw Error("validation requested but VK_LAYER_KHRONOS_validation is not installed (vulkan-validationlayers)");
    layers.push_back("VK_LAYER_KHRONOS_validation");
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    info.pNext = &debugInfo;  // also reports problems in vkCreateInstance / vkDestroyInstance
    if (options.syncValidation) {
      features.enabledValidationFeatureCount = 1;
      features.pEnabledValidationFeatures = &syncFeature;
      debugInfo.pNext = &features;
    }
  }
  info.enabledLayerCount = uint32_t(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  VK_CHECK(vkCreateInstance(&info, nullptr, &instance_));

  try {
    if (options.validation) {
      auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
      VkDebugUtilsMessengerCreateInfoEXT mi = messengerInfo();
      VK_CHECK(create(instance_, &mi, nullptr, &messenger_));
    }

    physical_ = choosePhysicalDevice(instance_, options.device);
    VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &driver};
    vkGetPhysicalDeviceProperties2(physical_, &props2);
    properties_ = props2.properties;
    driverInfo_ = std::string(driver.driverName) + " " + driver.driverInfo;
    if (properties_.apiVersion < VK_API_VERSION_1_3)
      throw Error(std::string("device '") + properties_.deviceName + "' supports only Vulkan " +
                  std::to_string(VK_API_VERSION_MAJOR(properties_.apiVersion)) + "." +
                  std::to_string(VK_API_VERSION_MINOR(properties_.apiVersion)) + "; 1.3 is required");

    // One queue that does graphics and compute (and present, where the app asks for it).
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &n, families.data());
    queueFamily_ = UINT32_MAX;
    for (uint32_t i = 0; i < n && queueFamily_ == UINT32_MAX; ++i)
      if ((families[i].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) ==
              (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT) &&
          families[i].timestampValidBits > 0)
        queueFamily_ = i;
    if (queueFamily_ == UINT32_MAX) throw Error("no queue family with graphics, compute and timestamps");

    // Features the renderer uses; all are in Vulkan 1.3 core or universally supported.
    VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    f13.dynamicRendering = VK_TRUE;
    f13.synchronization2 = VK_TRUE;
    f13.maintenance4 = VK_TRUE;  // SPIR-V 1.6 from glslang declares workgroup sizes with LocalSizeId
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &f13};
    f12.hostQueryReset = VK_TRUE;
    f12.runtimeDescriptorArray = VK_TRUE;  // one texture array sized by the scene
    f12.descriptorBindingPartiallyBound = VK_TRUE;
    f12.descriptorBindingVariableDescriptorCount = VK_TRUE;
    f12.shaderSampledImageArrayNonUniformIndexing = VK_TRUE;
    f12.scalarBlockLayout = VK_TRUE;
    VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
    f2.features.shaderStorageImageWriteWithoutFormat = VK_TRUE;
    // gl_PrimitiveID in fragment shaders (the renderer's visibility path) needs it; optional.
    VkPhysicalDeviceFeatures supported{};
    vkGetPhysicalDeviceFeatures(physical_, &supported);
    f2.features.geometryShader = supported.geometryShader;
    f2.features.samplerAnisotropy = supported.samplerAnisotropy;        // the viewer's --anisotropy; optional
    f2.features.textureCompressionBC = supported.textureCompressionBC;  // textures baked as BC; optional
    // The compute rasteriser (render/raster.hpp): 64-bit atomicMin on a storage buffer, also from the
    // fragment stage for the triangles it hands to the hardware; optional, enabled where all are supported.
    VkPhysicalDeviceVulkan12Features s12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceFeatures2 s2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &s12};
    vkGetPhysicalDeviceFeatures2(physical_, &s2);
    if (supported.shaderInt64 && supported.fragmentStoresAndAtomics && s12.shaderBufferInt64Atomics)
      f2.features.shaderInt64 = f2.features.fragmentStoresAndAtomics = f12.shaderBufferInt64Atomics = VK_TRUE;
    f12.descriptorBindingUpdateUnusedWhilePending = s12.descriptorBindingUpdateUnusedWhilePending;
    updateUnusedWhilePending_ = s12.descriptorBindingUpdateUnusedWhilePending;

    float priority = 1.0f;
    VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queueInfo.queueFamilyIndex = queueFamily_;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;
    // Push descriptors: per-dispatch bindings without pools (post-process, mip generation).
    std::vector<const char*> deviceExtensions{VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
    if (options.presentation) deviceExtensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    // Pipeline statistics (registers, spills, ...: --pipeline-stats), enabled only when asked for.
    uint32_t extensionCount = 0;
    vkEnumerateDeviceExtensionProperties(physical_, nullptr, &extensionCount, nullptr);
    std::vector<VkExtensionProperties> available(extensionCount);
    vkEnumerateDeviceExtensionProperties(physical_, nullptr, &extensionCount, available.data());
    for (const VkExtensionProperties& e : available)
      statisticsSupported_ |= std::strcmp(e.extensionName, VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME) == 0;
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR fExec{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR};
    if (statisticsSupported_) {
      VkPhysicalDeviceFeatures2 query{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &fExec};
      vkGetPhysicalDeviceFeatures2(physical_, &query);
      statisticsSupported_ = fExec.pipelineExecutableInfo;
    }
    const bool captureStatistics = options.pipelineStatistics && statisticsSupported_;
    if (captureStatistics) {
      deviceExtensions.push_back(VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
      fExec.pipelineExecutableInfo = VK_TRUE;
      fExec.pNext = f13.pNext;
      f13.pNext = &fExec;
    }
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f2};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &queueInfo;
    dci.enabledExtensionCount = uint32_t(deviceExtensions.size());
    dci.ppEnabledExtensionNames = deviceExtensions.data();
    checkCpuDeviceAddressSpace(properties_);
    VK_CHECK(vkCreateDevice(physical_, &dci, nullptr, &device_));
    pushDescriptorFn_ =
        reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(vkGetDeviceProcAddr(device_, "vkCmdPushDescriptorSetKHR"));
    vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);

    VmaAllocatorCreateInfo ai{};
    ai.physicalDevice = physical_;
    ai.device = device_;
    ai.instance = instance_;
    ai.vulkanApiVersion = VK_API_VERSION_1_3;
    VK_CHECK(vmaCreateAllocator(&ai, &allocator_));
    pipelineCache_ = std::make_unique<PipelineCache>(device_, properties_, options.pipelineCacheDir);
    executables_ = std::make_unique<PipelineExecutableLog>(device_, options.pipelineStatistics, captureStatistics);
  } catch (...) {
    release();
    throw;
  }
}

Context::~Context() { release(); }

void Context::release() {
  if (device_) vkDeviceWaitIdle(device_);
  pipelineCache_.reset();  // saves it
  if (allocator_) vmaDestroyAllocator(allocator_);
  if (device_) vkDestroyDevice(device_, nullptr);
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
  allocator_ = nullptr;
  device_ = VK_NULL_HANDLE;
  messenger_ = VK_NULL_HANDLE;
  instance_ = VK_NULL_HANDLE;
}

void Context::setName(uint64_t handle, VkObjectType type, const char* name) const {
  if (!messenger_) return;
  static auto fn =
      reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(vkGetInstanceProcAddr(instance_, "vkSetDebugUtilsObjectNameEXT"));
  VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
  info.objectType = type;
  info.objectHandle = handle;
  info.pObjectName = name;
  fn(device_, &info);
}

const char* resultName(VkResult r) {
  switch (r) {
#define CASE(x) \
  case x: return #x
    CASE(VK_SUCCESS);
    CASE(VK_NOT_READY);
    CASE(VK_TIMEOUT);
    CASE(VK_INCOMPLETE);
    CASE(VK_SUBOPTIMAL_KHR);
    CASE(VK_ERROR_OUT_OF_HOST_MEMORY);
    CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY);
    CASE(VK_ERROR_INITIALIZATION_FAILED);
    CASE(VK_ERROR_DEVICE_LOST);
    CASE(VK_ERROR_MEMORY_MAP_FAILED);
    CASE(VK_ERROR_LAYER_NOT_PRESENT);
    CASE(VK_ERROR_EXTENSION_NOT_PRESENT);
    CASE(VK_ERROR_FEATURE_NOT_PRESENT);
    CASE(VK_ERROR_INCOMPATIBLE_DRIVER);
    CASE(VK_ERROR_TOO_MANY_OBJECTS);
    CASE(VK_ERROR_FORMAT_NOT_SUPPORTED);
    CASE(VK_ERROR_SURFACE_LOST_KHR);
    CASE(VK_ERROR_OUT_OF_DATE_KHR);
    CASE(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR);
    CASE(VK_ERROR_OUT_OF_POOL_MEMORY);
    CASE(VK_ERROR_FRAGMENTED_POOL);
    CASE(VK_ERROR_UNKNOWN);
#undef CASE
    default: return "VkResult(?)";
  }
}

VkDeviceSize Context::deviceHeapBytes() const {
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(physical_, &mp);
  VkDeviceSize best = 0;
  for (uint32_t i = 0; i < mp.memoryHeapCount; ++i)
    if (mp.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) best = std::max(best, mp.memoryHeaps[i].size);
  return best;
}

}  // namespace rtr::vk
