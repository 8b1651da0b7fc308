// A C++ host that owns its Vulkan instance, device, queue, images and frame loop, and hands
// them to Tessera (host-owned mode) with dynamic rendering: for each technique it draws the
// spot mesh into its own colour + depth target inside its own dynamic-rendering scope, reads
// the image back and writes it to OUT_DIR/<technique>.rgba (raw RGBA8) for comparison with
// Tessera's own render of the same view. Between frames it captures what Tessera drew into its
// device (OUT_DIR/<technique>.obj, as `tessera export` writes it) and evaluates the exact limit
// surface at the captured vertices' `# p` points on four threads at once. It runs under the
// validation layer (synchronization validation included) with a debug messenger that counts
// every warning and error; it exits non-zero on any, on any Tessera failure, or on an image
// with too few lit pixels.
//
// Usage: cpp-host OUT_DIR [misuse]
//   With "misuse" it also checks that wrong calls get the right status codes and messages.
#include "tessera.hpp"
#include "vulkan_host.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

namespace {

constexpr uint32_t kWidth = 160;
constexpr uint32_t kHeight = 120;
constexpr VkExtent2D kExtent{kWidth, kHeight};
constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr uint32_t kFramesInFlight = 2;

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
    // Limit evaluation of a face the surface does not have, and of a NaN parameter.
    tessera::LimitEvaluator ev = tessera::LimitEvaluator::of_surface(ctx, s);
    uint32_t face = uint32_t(ev.face_count());
    double uv[2] = {0.5, 0.5};
    double out[3];
    expect(tessera_limit_evaluate(ev.get(), &face, uv, 1, out, nullptr, nullptr, nullptr),
           TESSERA_STATUS_INDEX_OUT_OF_RANGE, "limit face out of range", "point 0");
    face = 0;
    uv[1] = std::nan("");
    expect(tessera_limit_evaluate(ev.get(), &face, uv, 1, out, nullptr, nullptr, nullptr),
           TESSERA_STATUS_NON_FINITE, "limit NaN parameter", "NaN");
    // Use after destroy.
    TesseraSurface *gone = s.get();
    s.reset();
    expect(tessera_surface_set_frame(ctx.get(), gone, &frame), TESSERA_STATUS_DESTROYED_HANDLE,
           "use after destroy", "destroyed");
    expect(tessera_surface_destroy(ctx.get(), gone), TESSERA_STATUS_DESTROYED_HANDLE,
           "double destroy", "destroyed");
    return failures;
}

// The `# p F U V` points of a captured OBJ.
void read_points(const std::string &path, std::vector<uint32_t> &faces, std::vector<double> &uvs) {
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("# p ", 0) != 0) continue;
        std::istringstream words(line.substr(4));
        uint32_t f;
        double u, v;
        words >> f >> u >> v;
        faces.push_back(f);
        uvs.push_back(u);
        uvs.push_back(v);
    }
}

// Evaluates the captured vertices' points on one thread, then on four at once sharing the
// evaluator: the results must be identical and finite.
int check_limit(const tessera::LimitEvaluator &ev, const std::string &obj, const char *name) {
    std::vector<uint32_t> faces;
    std::vector<double> uvs;
    read_points(obj, faces, uvs);
    if (faces.empty()) {
        std::fprintf(stderr, "%s: no # p lines in %s\n", name, obj.c_str());
        return 1;
    }
    tessera::LimitEvaluator::Samples whole = ev.evaluate(faces, uvs);
    for (double x : whole.positions) {
        if (!std::isfinite(x)) {
            std::fprintf(stderr, "%s: a non-finite limit position\n", name);
            return 1;
        }
    }
    const size_t threads = 4, n = faces.size();
    std::vector<std::vector<double>> parts(threads);
    std::vector<std::thread> pool;
    for (size_t t = 0; t < threads; t++) {
        pool.emplace_back([&, t] {
            size_t begin = n * t / threads, end = n * (t + 1) / threads;
            std::vector<uint32_t> f(faces.begin() + begin, faces.begin() + end);
            std::vector<double> p(uvs.begin() + 2 * begin, uvs.begin() + 2 * end);
            parts[t] = ev.evaluate(f, p).positions;
        });
    }
    for (auto &th : pool) th.join();
    std::vector<double> joined;
    for (auto &p : parts) joined.insert(joined.end(), p.begin(), p.end());
    if (joined != whole.positions) {
        std::fprintf(stderr, "%s: evaluations on four threads differ from one\n", name);
        return 1;
    }
    return 0;
}

// One frame: pre-pass, the host's dynamic-rendering scope with Tessera's draws, readback.
std::vector<uint8_t> draw_frame(const host::Vulkan &vk, tessera::Context &ctx,
                                tessera::Surface &surface, const host::Image &color,
                                const host::Image &depth, const TesseraFrameDesc &frame,
                                const std::array<float, 16> &view,
                                const std::array<float, 16> &proj, uint64_t frame_index) {
    VkCommandBuffer cmd = vk.cmd;
    ctx.begin_frame(frame_index);
    vk.begin();
    surface.record_pre_pass(cmd);
    barrier(cmd, color.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, 0,
            VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
            VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
    barrier(cmd, depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
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
    rendering.renderArea = {{0, 0}, kExtent};
    rendering.layerCount = 1;
    rendering.colorAttachmentCount = 1;
    rendering.pColorAttachments = &color_att;
    rendering.pDepthAttachment = &depth_att;
    vkCmdBeginRendering(cmd, &rendering);
    // y flipped as Tessera's own targets are (+y up).
    VkViewport viewport{0, float(kHeight), float(kWidth), -float(kHeight), 0, 1};
    VkRect2D scissor{{0, 0}, kExtent};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
    surface.record_draw(cmd, view.data(), proj.data());
    vkCmdEndRendering(cmd);
    barrier(cmd, color.image, VK_IMAGE_ASPECT_COLOR_BIT,
            VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
            VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    vk.record_readback(color.image, kExtent);
    vk.submit_and_wait();
    return vk.read_pixels();
}

int run(const std::string &out_dir, bool misuse) {
    host::Vulkan vk("tessera cpp-host", host::DeviceOptions{}, VkDeviceSize(kWidth) * kHeight * 4);
    host::Image color = vk.make_image(
        kColorFormat, kExtent, VK_SAMPLE_COUNT_1_BIT,
        VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
        VK_IMAGE_ASPECT_COLOR_BIT);
    host::Image depth = vk.make_image(kDepthFormat, kExtent, VK_SAMPLE_COUNT_1_BIT,
                                      VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                                      VK_IMAGE_ASPECT_DEPTH_BIT);
    int failures = 0;
    {
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
        desc.pipeline_cache = TESSERA_PIPELINE_CACHE_OFF;
        tessera::Context ctx = tessera::Context::host(desc);

        const host::NamedTechnique techniques[] = {
            {"flat", TESSERA_TECHNIQUE_FLAT},         {"phong", TESSERA_TECHNIQUE_PHONG},
            {"pn", TESSERA_TECHNIQUE_PN},             {"bft", TESSERA_TECHNIQUE_BFT},
            {"adaptive", TESSERA_TECHNIQUE_ADAPTIVE}, {"gregory", TESSERA_TECHNIQUE_GREGORY},
            {"acc", TESSERA_TECHNIQUE_ACC}};
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
            auto draw = [&]() {
                return draw_frame(vk, ctx, surface, color, depth, frame, camera.first,
                                  camera.second, frame_index++);
            };
            std::vector<uint8_t> pixels = draw();
            if (host::lit_pixels(pixels, frame.clear_color) < size_t(kWidth) * kHeight / 20) {
                std::fprintf(stderr, "%s: too few pixels show the surface\n", t.name);
                failures++;
            }
            host::write_file(out_dir + "/" + t.name + ".rgba", pixels);
            // Between frames (the fence wait above): capture what Tessera drew, with the same
            // weld and report as standalone, and evaluate the limit at its vertices.
            if (vk.transform_feedback) {
                std::string obj = out_dir + "/" + t.name + ".obj";
                TesseraCaptureReport report = surface.capture(frame, obj.c_str());
                if (report.triangles == 0 || report.cracks != 0) {
                    std::fprintf(stderr, "%s: captured %llu triangles, %llu cracks\n", t.name,
                                 (unsigned long long)report.triangles,
                                 (unsigned long long)report.cracks);
                    failures++;
                }
                tessera::LimitEvaluator ev = tessera::LimitEvaluator::of_surface(ctx, surface);
                failures += check_limit(ev, obj, t.name);
            }
            // Animation, for the techniques that take it: the base moves once, in frame 2
            // (slot 1); frame 3 reuses slot 0, which must catch up with the move.
            if (t.technique == TESSERA_TECHNIQUE_BFT || t.technique == TESSERA_TECHNIQUE_ADAPTIVE) {
                std::vector<float> moved = surface.positions();
                for (float &x : moved) x *= 0.6f;
                ctx.begin_frame(frame_index);
                surface.update_positions(moved);
                std::vector<uint8_t> second = draw();
                std::vector<uint8_t> third = draw();
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
    vk.destroy_image(depth);
    vk.destroy_image(color);
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
        // The Vulkan objects are gone: the layer has reported anything left alive.
        if (host::g_errors != 0 || host::g_warnings != 0) {
            std::fprintf(stderr, "%d validation errors, %d warnings\n", host::g_errors,
                         host::g_warnings);
            failures++;
        }
        if (failures == 0) std::printf("cpp-host: 7 techniques drawn, 0 validation messages\n");
        return failures == 0 ? 0 : 1;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "cpp-host: %s\n", e.what());
        return 1;
    }
}
