// A C++ host built the way Vulkan 1.0–1.2 engines are: a VkRenderPass with a subpass, a
// framebuffer, vkCmdBeginRenderPass and version-1 pipeline barriers, on a device created
// without dynamicRendering or synchronization2. It hands Tessera its render pass, subpass and
// sample count (host-owned mode), and for each technique draws the spot mesh inside its own
// render pass instance, reads the image back and writes it to OUT_DIR/<technique>.rgba (raw
// RGBA8) for comparison with the dynamic-rendering host's and Tessera's own images. It also
// draws adaptive into a 4-sample render pass resolved into a 1-sample image
// (OUT_DIR/adaptive_msaa4.rgba). Validation (synchronization validation included) counts
// every warning and error; any, any Tessera failure or an image with too few lit pixels make
// it exit non-zero.
//
// Usage: cpp-host-renderpass OUT_DIR [misuse]
//   With "misuse" it also checks what a render-pass host can get wrong.
#include "tessera.hpp"
#include "vulkan_host.hpp"

#include <cstring>
#include <utility>

namespace {

constexpr uint32_t kWidth = 160;
constexpr uint32_t kHeight = 120;
constexpr VkExtent2D kExtent{kWidth, kHeight};
constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr uint32_t kFramesInFlight = 2;

// A render pass of one subpass drawing colour and depth with `samples` samples; with more than
// one, the colour resolves into a third, single-sample attachment. The image read back (the
// colour, or the resolve) ends in TRANSFER_SRC_OPTIMAL.
struct Pass {
    VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
    VkRenderPass render_pass = VK_NULL_HANDLE;
    VkFramebuffer framebuffer = VK_NULL_HANDLE;
    host::Image color, depth, resolve;

    Pass(const host::Vulkan &vk, VkSampleCountFlagBits s) : samples(s) {
        const bool msaa = samples != VK_SAMPLE_COUNT_1_BIT;
        VkAttachmentDescription attachments[3]{};
        attachments[0].format = kColorFormat;
        attachments[0].samples = samples;
        attachments[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        attachments[0].storeOp = msaa ? VK_ATTACHMENT_STORE_OP_DONT_CARE : VK_ATTACHMENT_STORE_OP_STORE;
        attachments[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
        attachments[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        attachments[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        attachments[0].finalLayout =
            msaa ? VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        attachments[1] = attachments[0];
        attachments[1].format = kDepthFormat;
        attachments[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        attachments[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        attachments[2] = attachments[0];
        attachments[2].samples = VK_SAMPLE_COUNT_1_BIT;
        attachments[2].loadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
        attachments[2].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        attachments[2].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        VkAttachmentReference color_ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
        VkAttachmentReference depth_ref{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
        VkAttachmentReference resolve_ref{2, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
        VkSubpassDescription subpass{};
        subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
        subpass.colorAttachmentCount = 1;
        subpass.pColorAttachments = &color_ref;
        subpass.pResolveAttachments = msaa ? &resolve_ref : nullptr;
        subpass.pDepthStencilAttachment = &depth_ref;
        // In: the previous frame's copy (a read) and attachment writes before this frame's
        // writes. Out: this frame's colour (or resolve) writes before the copy.
        VkSubpassDependency deps[2]{};
        deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
        deps[0].dstSubpass = 0;
        deps[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT |
                               VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                               VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
        deps[0].srcAccessMask =
            VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
        deps[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                               VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                               VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
        deps[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
                                VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                                VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
        deps[1].srcSubpass = 0;
        deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
        deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
        deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
        deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
        deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
        VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
        info.attachmentCount = msaa ? 3 : 2;
        info.pAttachments = attachments;
        info.subpassCount = 1;
        info.pSubpasses = &subpass;
        info.dependencyCount = 2;
        info.pDependencies = deps;
        host::vk_check(vkCreateRenderPass(vk.device, &info, nullptr, &render_pass),
                       "vkCreateRenderPass");
        color = vk.make_image(kColorFormat, kExtent, samples,
                              VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                                  (msaa ? 0 : VK_IMAGE_USAGE_TRANSFER_SRC_BIT),
                              VK_IMAGE_ASPECT_COLOR_BIT);
        depth = vk.make_image(kDepthFormat, kExtent, samples,
                              VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                              VK_IMAGE_ASPECT_DEPTH_BIT);
        if (msaa) {
            resolve = vk.make_image(
                kColorFormat, kExtent, VK_SAMPLE_COUNT_1_BIT,
                VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                VK_IMAGE_ASPECT_COLOR_BIT);
        }
        VkImageView views[3] = {color.view, depth.view, resolve.view};
        VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
        fb.renderPass = render_pass;
        fb.attachmentCount = info.attachmentCount;
        fb.pAttachments = views;
        fb.width = kWidth;
        fb.height = kHeight;
        fb.layers = 1;
        host::vk_check(vkCreateFramebuffer(vk.device, &fb, nullptr, &framebuffer),
                       "vkCreateFramebuffer");
    }

    VkImage read_image() const {
        return samples == VK_SAMPLE_COUNT_1_BIT ? color.image : resolve.image;
    }

    void destroy(const host::Vulkan &vk) {
        vkDestroyFramebuffer(vk.device, framebuffer, nullptr);
        vkDestroyRenderPass(vk.device, render_pass, nullptr);
        vk.destroy_image(color);
        vk.destroy_image(depth);
        if (resolve.image != VK_NULL_HANDLE) vk.destroy_image(resolve);
    }
};

TesseraHostDesc host_desc(const host::Vulkan &vk, const Pass &pass) {
    TesseraHostDesc desc{};
    desc.get_instance_proc_addr = vkGetInstanceProcAddr;
    desc.instance = vk.instance;
    desc.physical_device = vk.physical;
    desc.device = vk.device;
    desc.queue_family = vk.family;
    desc.queue = vk.queue;
    desc.color_format = kColorFormat;
    desc.depth_format = kDepthFormat;
    desc.frames_in_flight = kFramesInFlight;
    desc.debug_utils = 1;
    desc.transform_feedback = vk.transform_feedback ? 1 : 0;
    desc.vertex_pipeline_stores_and_atomics = vk.supported.vertexPipelineStoresAndAtomics;
    desc.buffer_device_address = 1;
    desc.render_pass = pass.render_pass;
    desc.subpass = 0;
    desc.samples = uint32_t(pass.samples);
    // This device was made without dynamicRendering.
    desc.dynamic_rendering = 0;
    desc.pipeline_cache = TESSERA_PIPELINE_CACHE_OFF;
    return desc;
}

// One frame: pre-pass, the host's render pass instance with Tessera's draws, readback.
std::vector<uint8_t> draw_frame(const host::Vulkan &vk, tessera::Context &ctx,
                                tessera::Surface &surface, const Pass &pass,
                                const TesseraFrameDesc &frame, const std::array<float, 16> &view,
                                const std::array<float, 16> &proj, uint64_t frame_index) {
    VkCommandBuffer cmd = vk.cmd;
    ctx.begin_frame(frame_index);
    vk.begin();
    surface.record_pre_pass(cmd);
    VkClearValue clear[2]{};
    std::memcpy(clear[0].color.float32, frame.clear_color, sizeof(float) * 4);
    clear[1].depthStencil = {1.0f, 0};
    VkRenderPassBeginInfo begin{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    begin.renderPass = pass.render_pass;
    begin.framebuffer = pass.framebuffer;
    begin.renderArea = {{0, 0}, kExtent};
    begin.clearValueCount = 2;
    begin.pClearValues = clear;
    vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
    // y flipped as Tessera's own targets are (+y up).
    VkViewport viewport{0, float(kHeight), float(kWidth), -float(kHeight), 0, 1};
    VkRect2D scissor{{0, 0}, kExtent};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
    surface.record_draw(cmd, view.data(), proj.data());
    vkCmdEndRenderPass(cmd);
    vk.record_readback(pass.read_image(), kExtent);
    vk.submit_and_wait();
    return vk.read_pixels();
}

// Draws spot with `technique` in `pass`; the image, or empty (counted) on too few lit pixels.
std::vector<uint8_t> draw_spot(const host::Vulkan &vk, tessera::Context &ctx, const Pass &pass,
                               TesseraTechnique technique, const char *name,
                               uint64_t &frame_index, int &failures) {
    TesseraSurfaceDesc sdesc = tessera::default_surface_desc();
    sdesc.technique = technique;
    tessera::Surface surface = tessera::Surface::from_obj(ctx, "", sdesc);
    TesseraFrameDesc frame = tessera::default_frame_desc();
    frame.width = kWidth;
    frame.height = kHeight;
    frame.factor = 4.0f;
    surface.set_frame(frame);
    auto camera = surface.camera(frame);
    std::vector<uint8_t> pixels =
        draw_frame(vk, ctx, surface, pass, frame, camera.first, camera.second, frame_index++);
    if (host::lit_pixels(pixels, frame.clear_color) < size_t(kWidth) * kHeight / 20) {
        std::fprintf(stderr, "%s: too few pixels show the surface\n", name);
        failures++;
    }
    return pixels;
}

int check_misuse(const host::Vulkan &vk, tessera::Context &ctx, const Pass &pass) {
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
    TesseraContext *raw = nullptr;
    TesseraHostDesc bad = host_desc(vk, pass);
    bad.samples = 3;
    expect(tessera_context_create_host(&bad, &raw), TESSERA_STATUS_INVALID_ARGUMENT,
           "3 samples", "samples 3");
    bad = host_desc(vk, pass);
    bad.render_pass = VK_NULL_HANDLE;
    bad.subpass = 1;
    expect(tessera_context_create_host(&bad, &raw), TESSERA_STATUS_INVALID_ARGUMENT,
           "subpass without a render pass", "render_pass is VK_NULL_HANDLE");
    // A capture renders into a dynamic-rendering scope of Tessera's own: refused on this
    // device, which lacks dynamicRendering, before any Vulkan call.
    tessera::Surface s = tessera::Surface::from_obj(ctx, "");
    TesseraFrameDesc frame = tessera::default_frame_desc();
    expect(tessera_capture(ctx.get(), s.get(), &frame, nullptr, nullptr),
           TESSERA_STATUS_UNSUPPORTED, "capture without dynamicRendering", "dynamicRendering");
    // The planned-patch techniques, BFT (its tables) and Doo-Sabin (its deepest level) read
    // arrays by device address: refused by name on a host that does not say it enabled
    // bufferDeviceAddress.
    TesseraHostDesc no_address = host_desc(vk, pass);
    no_address.buffer_device_address = 0;
    tessera::Context plain = tessera::Context::host(no_address);
    const std::pair<TesseraTechnique, const char *> by_address[] = {
        {TESSERA_TECHNIQUE_ADAPTIVE, "adaptive without bufferDeviceAddress"},
        {TESSERA_TECHNIQUE_BFT, "bft without bufferDeviceAddress"},
        {TESSERA_TECHNIQUE_DOO_SABIN, "doo-sabin without bufferDeviceAddress"},
    };
    for (const auto &[technique, what] : by_address) {
        TesseraSurfaceDesc sdesc = tessera::default_surface_desc();
        sdesc.technique = technique;
        TesseraSurface *none = nullptr;
        expect(tessera_surface_create_obj(plain.get(), nullptr, 0, nullptr, &sdesc, &none),
               TESSERA_STATUS_UNSUPPORTED, what, "bufferDeviceAddress");
    }
    return failures;
}

int run(const std::string &out_dir, bool misuse) {
    host::DeviceOptions options;
    options.dynamic_rendering = false;
    host::Vulkan vk("tessera cpp-host-renderpass", options, VkDeviceSize(kWidth) * kHeight * 4);
    Pass single(vk, VK_SAMPLE_COUNT_1_BIT);
    Pass msaa(vk, VK_SAMPLE_COUNT_4_BIT);
    int failures = 0;
    {
        tessera::Context ctx = tessera::Context::host(host_desc(vk, single));
        const host::NamedTechnique techniques[] = {
            {"flat", TESSERA_TECHNIQUE_FLAT},         {"phong", TESSERA_TECHNIQUE_PHONG},
            {"pn", TESSERA_TECHNIQUE_PN},             {"bft", TESSERA_TECHNIQUE_BFT},
            {"adaptive", TESSERA_TECHNIQUE_ADAPTIVE}, {"gregory", TESSERA_TECHNIQUE_GREGORY},
            {"acc", TESSERA_TECHNIQUE_ACC}};
        uint64_t frame_index = 0;
        for (const auto &t : techniques) {
            host::write_file(out_dir + "/" + t.name + ".rgba",
                             draw_spot(vk, ctx, single, t.technique, t.name, frame_index,
                                       failures));
        }
        if (misuse) failures += check_misuse(vk, ctx, single);
        // A second context for the 4-sample render pass: its pipelines rasterize 4 samples.
        tessera::Context ctx4 = tessera::Context::host(host_desc(vk, msaa));
        uint64_t frame4 = 0;
        host::write_file(out_dir + "/adaptive_msaa4.rgba",
                         draw_spot(vk, ctx4, msaa, TESSERA_TECHNIQUE_ADAPTIVE, "adaptive 4x",
                                   frame4, failures));
    }
    msaa.destroy(vk);
    single.destroy(vk);
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
        if (host::g_errors != 0 || host::g_warnings != 0) {
            std::fprintf(stderr, "%d validation errors, %d warnings\n", host::g_errors,
                         host::g_warnings);
            failures++;
        }
        if (failures == 0) {
            std::printf("cpp-host-renderpass: 7 techniques drawn, 0 validation messages\n");
        }
        return failures == 0 ? 0 : 1;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "cpp-host-renderpass: %s\n", e.what());
        return 1;
    }
}
