// What both example hosts share: a Vulkan instance with validation (synchronization validation
// included) and a messenger of the host's own that counts every warning and error, a device
// with the features Tessera needs, images, a readback buffer, one command buffer and a fence.
// Each example's main.cpp holds what differs: how it renders (dynamic rendering or a render
// pass) and what it checks.
#ifndef TESSERA_EXAMPLE_VULKAN_HOST_HPP
#define TESSERA_EXAMPLE_VULKAN_HOST_HPP

#include <vulkan/vulkan.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace host {

inline int g_errors = 0;
inline int g_warnings = 0;

inline VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                 VkDebugUtilsMessageTypeFlagsEXT,
                                                 const VkDebugUtilsMessengerCallbackDataEXT *data,
                                                 void *) {
    if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
        g_errors++;
        std::fprintf(stderr, "validation error: %s\n", data->pMessage);
    } else if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        g_warnings++;
        std::fprintf(stderr, "validation warning: %s\n", data->pMessage);
    }
    return VK_FALSE;
}

inline void vk_check(VkResult r, const char *what) {
    if (r != VK_SUCCESS) {
        throw std::runtime_error(std::string(what) + " failed: " + std::to_string(r));
    }
}

inline uint32_t memory_type(VkPhysicalDevice physical, uint32_t bits, VkMemoryPropertyFlags want) {
    VkPhysicalDeviceMemoryProperties props;
    vkGetPhysicalDeviceMemoryProperties(physical, &props);
    for (uint32_t i = 0; i < props.memoryTypeCount; i++) {
        if ((bits & (1u << i)) && (props.memoryTypes[i].propertyFlags & want) == want) return i;
    }
    throw std::runtime_error("no suitable memory type");
}

struct Image {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
};

// What the device is created with.
struct DeviceOptions {
    // Enable dynamicRendering (and synchronization2): a render-pass engine may leave it off.
    bool dynamic_rendering = true;
};

// The instance, device, queue and frame objects of a host, destroyed in reverse order.
struct Vulkan {
    VkInstance instance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger = nullptr;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkPhysicalDeviceFeatures supported{};
    bool transform_feedback = false;
    uint32_t family = 0;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    VkCommandPool pool = VK_NULL_HANDLE;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    VkBuffer readback = VK_NULL_HANDLE;
    VkDeviceMemory readback_memory = VK_NULL_HANDLE;
    VkDeviceSize readback_size = 0;

    Vulkan(const char *name, DeviceOptions options, VkDeviceSize readback_bytes) {
        create_instance(name);
        choose_device();
        create_device(options);
        create_frame_objects(readback_bytes);
    }
    Vulkan(const Vulkan &) = delete;
    Vulkan &operator=(const Vulkan &) = delete;

    ~Vulkan() {
        vkDestroyFence(device, fence, nullptr);
        vkDestroyCommandPool(device, pool, nullptr);
        vkDestroyBuffer(device, readback, nullptr);
        vkFreeMemory(device, readback_memory, nullptr);
        vkDestroyDevice(device, nullptr);
        destroy_messenger(instance, messenger, nullptr);
        vkDestroyInstance(instance, nullptr);
    }

    Image make_image(VkFormat format, VkExtent2D extent, VkSampleCountFlagBits samples,
                     VkImageUsageFlags usage, VkImageAspectFlags aspect) const {
        Image img;
        VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
        info.imageType = VK_IMAGE_TYPE_2D;
        info.format = format;
        info.extent = {extent.width, extent.height, 1};
        info.mipLevels = 1;
        info.arrayLayers = 1;
        info.samples = samples;
        info.tiling = VK_IMAGE_TILING_OPTIMAL;
        info.usage = usage;
        vk_check(vkCreateImage(device, &info, nullptr, &img.image), "vkCreateImage");
        VkMemoryRequirements req;
        vkGetImageMemoryRequirements(device, img.image, &req);
        VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex =
            memory_type(physical, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        vk_check(vkAllocateMemory(device, &alloc, nullptr, &img.memory), "vkAllocateMemory");
        vk_check(vkBindImageMemory(device, img.image, img.memory, 0), "vkBindImageMemory");
        VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
        view.image = img.image;
        view.viewType = VK_IMAGE_VIEW_TYPE_2D;
        view.format = format;
        view.subresourceRange = {aspect, 0, 1, 0, 1};
        vk_check(vkCreateImageView(device, &view, nullptr, &img.view), "vkCreateImageView");
        return img;
    }

    void destroy_image(Image &img) const {
        vkDestroyImageView(device, img.view, nullptr);
        vkDestroyImage(device, img.image, nullptr);
        vkFreeMemory(device, img.memory, nullptr);
        img = Image{};
    }

    void begin() const {
        VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        vk_check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
    }

    // Ends the command buffer, submits it and waits for its fence (the frame is finished).
    void submit_and_wait() const {
        vk_check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
        VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
        submit.commandBufferCount = 1;
        submit.pCommandBuffers = &cmd;
        vk_check(vkQueueSubmit(queue, 1, &submit, fence), "vkQueueSubmit");
        vk_check(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
        vk_check(vkResetFences(device, 1, &fence), "vkResetFences");
    }

    // Records the copy of `image` (in TRANSFER_SRC_OPTIMAL, its writes made visible to
    // transfers) into the readback buffer and the barrier that makes it visible to the host.
    void record_readback(VkImage image, VkExtent2D extent) const {
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {extent.width, extent.height, 1};
        vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback, 1,
                               &region);
        VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                             &to_host, 0, nullptr, 0, nullptr);
    }

    std::vector<uint8_t> read_pixels() const {
        void *mapped = nullptr;
        vk_check(vkMapMemory(device, readback_memory, 0, VK_WHOLE_SIZE, 0, &mapped),
                 "vkMapMemory");
        std::vector<uint8_t> pixels(static_cast<uint8_t *>(mapped),
                                    static_cast<uint8_t *>(mapped) + readback_size);
        vkUnmapMemory(device, readback_memory);
        return pixels;
    }

private:
    void create_instance(const char *name) {
        const char *layers[] = {"VK_LAYER_KHRONOS_validation"};
        const char *instance_exts[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
        VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
        app.pApplicationName = name;
        app.apiVersion = VK_API_VERSION_1_3;
        VkValidationFeatureEnableEXT sync =
            VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
        VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
        features.enabledValidationFeatureCount = 1;
        features.pEnabledValidationFeatures = &sync;
        VkDebugUtilsMessengerCreateInfoEXT messenger_info{
            VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
        messenger_info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                                         VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
        messenger_info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                                     VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
        messenger_info.pfnUserCallback = on_message;
        features.pNext = &messenger_info;
        VkInstanceCreateInfo instance_info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
        instance_info.pNext = &features;
        instance_info.pApplicationInfo = &app;
        instance_info.enabledLayerCount = 1;
        instance_info.ppEnabledLayerNames = layers;
        instance_info.enabledExtensionCount = 1;
        instance_info.ppEnabledExtensionNames = instance_exts;
        vk_check(vkCreateInstance(&instance_info, nullptr, &instance), "vkCreateInstance");
        auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
        destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
        vk_check(create_messenger(instance, &messenger_info, nullptr, &messenger),
                 "vkCreateDebugUtilsMessengerEXT");
    }

    // The first device with tessellation, and its first graphics + compute family.
    void choose_device() {
        uint32_t count = 0;
        vkEnumeratePhysicalDevices(instance, &count, nullptr);
        std::vector<VkPhysicalDevice> physicals(count);
        vkEnumeratePhysicalDevices(instance, &count, physicals.data());
        for (VkPhysicalDevice p : physicals) {
            VkPhysicalDeviceFeatures f;
            vkGetPhysicalDeviceFeatures(p, &f);
            uint32_t n = 0;
            vkGetPhysicalDeviceQueueFamilyProperties(p, &n, nullptr);
            std::vector<VkQueueFamilyProperties> families(n);
            vkGetPhysicalDeviceQueueFamilyProperties(p, &n, families.data());
            const VkQueueFlags both = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
            for (uint32_t i = 0; i < n && physical == VK_NULL_HANDLE; i++) {
                if (f.tessellationShader && (families[i].queueFlags & both) == both) {
                    physical = p;
                    family = i;
                }
            }
        }
        if (physical == VK_NULL_HANDLE) throw std::runtime_error("no device with tessellation");
        vkGetPhysicalDeviceFeatures(physical, &supported);
    }

    // The features Tessera states it needs; the optional ones are told to Tessera by the host.
    // VK_EXT_transform_feedback (captures) is enabled where the device has it.
    void create_device(DeviceOptions options) {
        float priority = 1.0f;
        VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        queue_info.queueFamilyIndex = family;
        queue_info.queueCount = 1;
        queue_info.pQueuePriorities = &priority;
        VkPhysicalDeviceTransformFeedbackFeaturesEXT xfb_supported{
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TRANSFORM_FEEDBACK_FEATURES_EXT};
        VkPhysicalDeviceFeatures2 features2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
        features2.pNext = &xfb_supported;
        vkGetPhysicalDeviceFeatures2(physical, &features2);
        transform_feedback = xfb_supported.transformFeedback == VK_TRUE;
        VkPhysicalDeviceTransformFeedbackFeaturesEXT xfb{
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TRANSFORM_FEEDBACK_FEATURES_EXT};
        xfb.transformFeedback = VK_TRUE;
        VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
        f13.dynamicRendering = options.dynamic_rendering ? VK_TRUE : VK_FALSE;
        f13.synchronization2 = options.dynamic_rendering ? VK_TRUE : VK_FALSE;
        f13.pNext = transform_feedback ? &xfb : nullptr;
        VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
        f12.timelineSemaphore = VK_TRUE;
        // Required in Vulkan 1.3; Tessera's planned-patch techniques read their arrays by address.
        f12.bufferDeviceAddress = VK_TRUE;
        f12.pNext = &f13;
        VkPhysicalDeviceFeatures base{};
        base.tessellationShader = VK_TRUE;
        base.fillModeNonSolid = VK_TRUE;
        base.vertexPipelineStoresAndAtomics = supported.vertexPipelineStoresAndAtomics;
        const char *xfb_ext[] = {VK_EXT_TRANSFORM_FEEDBACK_EXTENSION_NAME};
        VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
        device_info.pNext = &f12;
        device_info.queueCreateInfoCount = 1;
        device_info.pQueueCreateInfos = &queue_info;
        device_info.pEnabledFeatures = &base;
        device_info.enabledExtensionCount = transform_feedback ? 1 : 0;
        device_info.ppEnabledExtensionNames = xfb_ext;
        vk_check(vkCreateDevice(physical, &device_info, nullptr, &device), "vkCreateDevice");
        vkGetDeviceQueue(device, family, 0, &queue);
    }

    void create_frame_objects(VkDeviceSize readback_bytes) {
        readback_size = readback_bytes;
        VkBufferCreateInfo buffer_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
        buffer_info.size = readback_bytes;
        buffer_info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        vk_check(vkCreateBuffer(device, &buffer_info, nullptr, &readback), "vkCreateBuffer");
        VkMemoryRequirements req;
        vkGetBufferMemoryRequirements(device, readback, &req);
        VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex = memory_type(
            physical, req.memoryTypeBits,
            VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        vk_check(vkAllocateMemory(device, &alloc, nullptr, &readback_memory), "vkAllocateMemory");
        vk_check(vkBindBufferMemory(device, readback, readback_memory, 0), "vkBindBufferMemory");
        VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
        pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        pool_info.queueFamilyIndex = family;
        vk_check(vkCreateCommandPool(device, &pool_info, nullptr, &pool), "vkCreateCommandPool");
        VkCommandBufferAllocateInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
        cmd_info.commandPool = pool;
        cmd_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        cmd_info.commandBufferCount = 1;
        vk_check(vkAllocateCommandBuffers(device, &cmd_info, &cmd), "vkAllocateCommandBuffers");
        VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        vk_check(vkCreateFence(device, &fence_info, nullptr, &fence), "vkCreateFence");
    }
};

// Pixels of an RGBA8 image that differ from the clear colour by more than 2 in some channel.
inline size_t lit_pixels(const std::vector<uint8_t> &pixels, const float clear[4]) {
    size_t lit = 0;
    for (size_t i = 0; i + 3 < pixels.size(); i += 4) {
        for (int c = 0; c < 3; c++) {
            int want = int(clear[c] * 255.0f + 0.5f);
            int got = int(pixels[i + c]);
            if (got - want > 2 || want - got > 2) {
                lit++;
                break;
            }
        }
    }
    return lit;
}

inline void write_file(const std::string &path, const std::vector<uint8_t> &bytes) {
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char *>(bytes.data()), std::streamsize(bytes.size()));
}

// The techniques both hosts draw, by name (the names of `tessera render --method`).
struct NamedTechnique {
    const char *name;
    uint32_t technique;
};

} // namespace host

#endif
