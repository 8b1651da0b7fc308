// A C++ host that owns its Vulkan instance, device, queue, images and frame loop, and hands
// them to Tessera (host-owned mode): for each technique it draws the spot mesh into its own
// colour + depth target inside its own dynamic-rendering scope, reads the image back and writes
// it to OUT_DIR/<technique>.rgba (raw RGBA8) for comparison with Tessera's own render of the
// same view. It runs under the validation layer (synchronization validation included) with a
// debug messenger that counts every warning and error; it exits non-zero on any, on any Tessera
// failure, or on an image with too few lit pixels.
//
// Usage: cpp-host OUT_DIR [misuse]
//   With "misuse" it also checks that wrong calls get the right status codes and messages.
#include "tessera.hpp"

#include <vulkan/vulkan.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

constexpr uint32_t kWidth = 160;
constexpr uint32_t kHeight = 120;
constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr uint32_t kFramesInFlight = 2;

int g_errors = 0;
int g_warnings = 0;

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
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

void vk_check(VkResult r, const char *what) {
    if (r != VK_SUCCESS) {
        throw std::runtime_error(std::string(what) + " failed: " + std::to_string(r));
    }
}

uint32_t memory_type(VkPhysicalDevice physical, uint32_t bits, VkMemoryPropertyFlags want) {
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

Image make_image(VkPhysicalDevice physical, VkDevice device, VkFormat format,
                 VkImageUsageFlags usage, VkImageAspectFlags aspect) {
    Image img;
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {kWidth, kHeight, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
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

void destroy_image(VkDevice device, Image &img) {
    vkDestroyImageView(device, img.view, nullptr);
    vkDestroyImage(device, img.image, nullptr);
    vkFreeMemory(device, img.memory, nullptr);
}

void barrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect,
             VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
             VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access, VkImageLayout from,
             VkImageLayout to) {
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = src_stage;
    b.srcAccessMask = src_access;
    b.dstStageMask = dst_stage;
    b.dstAccessMask = dst_access;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspect, 0, 1, 0, 1};
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
}

// Misuse through the C++ wrapper and the C ABI: each must fail with its code and a message.
int check_misuse(tessera::Context &ctx) {
    int failures = 0;
    auto expect = [&](TesseraStatus got, TesseraStatus want, const char *what,
                      const char *needle) {
        std::string message = tessera::last_error(nullptr);
        if (got != want || message.find(needle) == std::string::npos) {
            std::fprintf(stderr, "misuse %s: got %s (%s), want %s mentioning '%s'\n", what,
                         tessera_status_name(got), message.c_str(), tessera_status_name(want),
                         needle);
            failures++;
        }
    };
    float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    expect(tessera_record_draw(nullptr, nullptr, VK_NULL_HANDLE, m, m), TESSERA_STATUS_NULL_HANDLE,
           "null context", "null");
    // Standalone-only calls on a host-owned context.
    tessera::Surface s = tessera::Surface::from_obj(ctx, "");
    TesseraFrameDesc frame = tessera::default_frame_desc();
    std::vector<uint8_t> px(size_t(frame.width) * frame.height * 4);
    expect(tessera_render(ctx.get(), s.get(), &frame, px.data(), px.size()),
           TESSERA_STATUS_WRONG_MODE, "render on host context", "standalone");
    // A Loop surface from quads.
    TesseraSurfaceDesc loop = tessera::default_surface_desc();
    loop.technique = TESSERA_TECHNIQUE_BFT;
    loop.scheme = TESSERA_SCHEME_LOOP;
    TesseraSurface *raw = nullptr;
    expect(tessera_surface_create_obj(ctx.get(), nullptr, 0, nullptr, &loop, &raw),
           TESSERA_STATUS_MESH, "Loop on quads", "triangle");
    // An exception from the wrapper carries the status and the message.
    try {
        tessera::Surface::from_obj(ctx, "v 0 0 0\nf 1 2 3\n");
        std::fprintf(stderr, "misuse: a face with missing vertices was accepted\n");
        failures++;
    } catch (const tessera::Error &e) {
        if (e.status() != TESSERA_STATUS_INDEX_OUT_OF_RANGE &&
            e.status() != TESSERA_STATUS_PARSE) {
            std::fprintf(stderr, "misuse: bad OBJ gave %s\n", e.what());
            failures++;
        }
    }
    // Use after destroy.
    TesseraSurface *gone = s.get();
    s.reset();
    expect(tessera_surface_set_frame(ctx.get(), gone, &frame), TESSERA_STATUS_DESTROYED_HANDLE,
           "use after destroy", "destroyed");
    expect(tessera_surface_destroy(ctx.get(), gone), TESSERA_STATUS_DESTROYED_HANDLE,
           "double destroy", "destroyed");
    return failures;
}

int run(const std::string &out_dir, bool misuse) {
    // Instance: validation (with synchronization validation) and a messenger of our own.
    const char *layers[] = {"VK_LAYER_KHRONOS_validation"};
    const char *instance_exts[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "tessera cpp-host";
    app.apiVersion = VK_API_VERSION_1_3;
    VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
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
    VkInstance instance;
    vk_check(vkCreateInstance(&instance_info, nullptr, &instance), "vkCreateInstance");
    auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    auto destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
    VkDebugUtilsMessengerEXT messenger;
    vk_check(create_messenger(instance, &messenger_info, nullptr, &messenger),
             "vkCreateDebugUtilsMessengerEXT");

    // The first device with tessellation, and its first graphics + compute family.
    uint32_t count = 0;
    vkEnumeratePhysicalDevices(instance, &count, nullptr);
    std::vector<VkPhysicalDevice> physicals(count);
    vkEnumeratePhysicalDevices(instance, &count, physicals.data());
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    uint32_t family = 0;
    for (VkPhysicalDevice p : physicals) {
        VkPhysicalDeviceFeatures f;
        vkGetPhysicalDeviceFeatures(p, &f);
        uint32_t n = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(p, &n, nullptr);
        std::vector<VkQueueFamilyProperties> families(n);
        vkGetPhysicalDeviceQueueFamilyProperties(p, &n, families.data());
        for (uint32_t i = 0; i < n && physical == VK_NULL_HANDLE; i++) {
            if (f.tessellationShader &&
                (families[i].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) ==
                    (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) {
                physical = p;
                family = i;
            }
        }
    }
    if (physical == VK_NULL_HANDLE) throw std::runtime_error("no device with tessellation");
    VkPhysicalDeviceFeatures supported;
    vkGetPhysicalDeviceFeatures(physical, &supported);

    // The features Tessera states it needs; the optional ones told to Tessera below.
    float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queue_info.queueFamilyIndex = family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    f13.dynamicRendering = VK_TRUE;
    f13.synchronization2 = VK_TRUE;
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    f12.timelineSemaphore = VK_TRUE;
    f12.pNext = &f13;
    VkPhysicalDeviceFeatures base{};
    base.tessellationShader = VK_TRUE;
    base.fillModeNonSolid = VK_TRUE;
    base.vertexPipelineStoresAndAtomics = supported.vertexPipelineStoresAndAtomics;
    VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    device_info.pNext = &f12;
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    device_info.pEnabledFeatures = &base;
    VkDevice device;
    vk_check(vkCreateDevice(physical, &device_info, nullptr, &device), "vkCreateDevice");
    VkQueue queue;
    vkGetDeviceQueue(device, family, 0, &queue);

    // The host's own target, readback buffer, command buffer and fence.
    Image color = make_image(physical, device, kColorFormat,
                             VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                             VK_IMAGE_ASPECT_COLOR_BIT);
    Image depth = make_image(physical, device, kDepthFormat,
                             VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                             VK_IMAGE_ASPECT_DEPTH_BIT);
    VkBufferCreateInfo buffer_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    buffer_info.size = VkDeviceSize(kWidth) * kHeight * 4;
    buffer_info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkBuffer readback;
    vk_check(vkCreateBuffer(device, &buffer_info, nullptr, &readback), "vkCreateBuffer");
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, readback, &req);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex =
        memory_type(physical, req.memoryTypeBits,
                    VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    VkDeviceMemory readback_memory;
    vk_check(vkAllocateMemory(device, &alloc, nullptr, &readback_memory), "vkAllocateMemory");
    vk_check(vkBindBufferMemory(device, readback, readback_memory, 0), "vkBindBufferMemory");
    VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool_info.queueFamilyIndex = family;
    VkCommandPool pool;
    vk_check(vkCreateCommandPool(device, &pool_info, nullptr, &pool), "vkCreateCommandPool");
    VkCommandBufferAllocateInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cmd_info.commandPool = pool;
    cmd_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cmd_info.commandBufferCount = 1;
    VkCommandBuffer cmd;
    vk_check(vkAllocateCommandBuffers(device, &cmd_info, &cmd), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence;
    vk_check(vkCreateFence(device, &fence_info, nullptr, &fence), "vkCreateFence");

    int failures = 0;
    {
        TesseraHostDesc desc{};
        desc.get_instance_proc_addr = vkGetInstanceProcAddr;
        desc.instance = instance;
        desc.physical_device = physical;
        desc.device = device;
        desc.queue_family = family;
        desc.queue = queue;
        desc.color_format = kColorFormat;
        desc.depth_format = kDepthFormat;
        desc.frames_in_flight = kFramesInFlight;
        desc.debug_utils = 1;
        desc.vertex_pipeline_stores_and_atomics = supported.vertexPipelineStoresAndAtomics;
        tessera::Context ctx = tessera::Context::host(desc);

        const struct {
            const char *name;
            TesseraTechnique technique;
        } techniques[] = {{"flat", TESSERA_TECHNIQUE_FLAT},
                          {"phong", TESSERA_TECHNIQUE_PHONG},
                          {"pn", TESSERA_TECHNIQUE_PN},
                          {"bft", TESSERA_TECHNIQUE_BFT},
                          {"adaptive", TESSERA_TECHNIQUE_ADAPTIVE}};
        uint64_t frame_index = 0;
        for (const auto &t : techniques) {
            TesseraSurfaceDesc sdesc = tessera::default_surface_desc();
            sdesc.technique = t.technique;
            tessera::Surface surface = tessera::Surface::from_obj(ctx, "", sdesc);
            TesseraFrameDesc frame = tessera::default_frame_desc();
            frame.width = kWidth;
            frame.height = kHeight;
            frame.factor = 4.0f;
            surface.set_frame(frame);
            // The view `tessera render` uses, so the images can be compared.
            auto camera = surface.camera(frame);

            // One frame: record, submit, wait, read back.
            auto draw_frame = [&]() {
                ctx.begin_frame(frame_index++);
                VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
                begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
                vk_check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
                surface.record_pre_pass(cmd);
                barrier(cmd, color.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, 0,
                        VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                        VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                        VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
                barrier(cmd, depth.image, VK_IMAGE_ASPECT_DEPTH_BIT,
                        VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                        VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                        VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                            VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                        VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                            VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                        VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
                VkRenderingAttachmentInfo color_att{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
                color_att.imageView = color.view;
                color_att.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
                color_att.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
                color_att.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
                std::memcpy(color_att.clearValue.color.float32, frame.clear_color, sizeof(float) * 4);
                VkRenderingAttachmentInfo depth_att{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
                depth_att.imageView = depth.view;
                depth_att.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
                depth_att.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
                depth_att.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
                depth_att.clearValue.depthStencil = {1.0f, 0};
                VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
                rendering.renderArea = {{0, 0}, {kWidth, kHeight}};
                rendering.layerCount = 1;
                rendering.colorAttachmentCount = 1;
                rendering.pColorAttachments = &color_att;
                rendering.pDepthAttachment = &depth_att;
                vkCmdBeginRendering(cmd, &rendering);
                // y flipped as Tessera's own targets are (+y up).
                VkViewport viewport{0, float(kHeight), float(kWidth), -float(kHeight), 0, 1};
                VkRect2D scissor{{0, 0}, {kWidth, kHeight}};
                vkCmdSetViewport(cmd, 0, 1, &viewport);
                vkCmdSetScissor(cmd, 0, 1, &scissor);
                surface.record_draw(cmd, camera.first.data(), camera.second.data());
                vkCmdEndRendering(cmd);
                barrier(cmd, color.image, VK_IMAGE_ASPECT_COLOR_BIT,
                        VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                        VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                        VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                        VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
                VkBufferImageCopy region{};
                region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                region.imageExtent = {kWidth, kHeight, 1};
                vkCmdCopyImageToBuffer(cmd, color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                       readback, 1, &region);
                VkMemoryBarrier2 to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
                to_host.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
                to_host.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
                to_host.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
                to_host.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
                VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
                dep.memoryBarrierCount = 1;
                dep.pMemoryBarriers = &to_host;
                vkCmdPipelineBarrier2(cmd, &dep);
                vk_check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
                VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
                submit.commandBufferCount = 1;
                submit.pCommandBuffers = &cmd;
                vk_check(vkQueueSubmit(queue, 1, &submit, fence), "vkQueueSubmit");
                vk_check(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
                vk_check(vkResetFences(device, 1, &fence), "vkResetFences");

                void *mapped = nullptr;
                vk_check(vkMapMemory(device, readback_memory, 0, VK_WHOLE_SIZE, 0, &mapped),
                         "vkMapMemory");
                std::vector<uint8_t> pixels(static_cast<uint8_t *>(mapped),
                                            static_cast<uint8_t *>(mapped) + buffer_info.size);
                vkUnmapMemory(device, readback_memory);
                return pixels;
            };
            std::vector<uint8_t> pixels = draw_frame();
            size_t lit = 0;
            for (size_t i = 0; i < size_t(kWidth) * kHeight; i++) {
                for (int c = 0; c < 3; c++) {
                    int clear = int(frame.clear_color[c] * 255.0f + 0.5f);
                    if (std::abs(int(pixels[4 * i + c]) - clear) > 2) {
                        lit++;
                        break;
                    }
                }
            }
            if (lit < size_t(kWidth) * kHeight / 20) {
                std::fprintf(stderr, "%s: only %zu pixels show the surface\n", t.name, lit);
                failures++;
            }
            std::ofstream(out_dir + "/" + t.name + ".rgba", std::ios::binary)
                .write(reinterpret_cast<const char *>(pixels.data()), std::streamsize(pixels.size()));
            // Animation, for the techniques that take it: the base moves once, in frame 2
            // (slot 1); frame 3 reuses slot 0, which must catch up with the move.
            if (t.technique == TESSERA_TECHNIQUE_BFT || t.technique == TESSERA_TECHNIQUE_ADAPTIVE) {
                std::vector<float> moved = surface.positions();
                for (float &x : moved) x *= 0.6f;
                ctx.begin_frame(frame_index);
                surface.update_positions(moved);
                std::vector<uint8_t> second = draw_frame();
                std::vector<uint8_t> third = draw_frame();
                if (second == pixels) {
                    std::fprintf(stderr, "%s: moving the base changed nothing\n", t.name);
                    failures++;
                }
                if (third != second) {
                    std::fprintf(stderr, "%s: the next frame slot did not catch up\n", t.name);
                    failures++;
                }
            }
            // The fence waits above mean the GPU finished with the surface: it may go now.
        }
        if (misuse) failures += check_misuse(ctx);
        // Tessera goes before the device it was given (and destroys nothing of the host's).
    }

    vkDestroyFence(device, fence, nullptr);
    vkDestroyCommandPool(device, pool, nullptr);
    vkDestroyBuffer(device, readback, nullptr);
    vkFreeMemory(device, readback_memory, nullptr);
    destroy_image(device, depth);
    destroy_image(device, color);
    vkDestroyDevice(device, nullptr);
    destroy_messenger(instance, messenger, nullptr);
    vkDestroyInstance(instance, nullptr);
    if (g_errors != 0 || g_warnings != 0) {
        std::fprintf(stderr, "%d validation errors, %d warnings\n", g_errors, g_warnings);
        failures++;
    }
    return failures;
}

} // namespace

int main(int argc, char **argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s OUT_DIR [misuse]\n", argv[0]);
        return 2;
    }
    try {
        int failures = run(argv[1], argc > 2 && std::string(argv[2]) == "misuse");
        if (failures == 0) std::printf("cpp-host: 5 techniques drawn, 0 validation messages\n");
        return failures == 0 ? 0 : 1;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "cpp-host: %s\n", e.what());
        return 1;
    }
}
