// Tessera C++17 wrapper: move-only RAII handles over the C ABI of tessera.h.
//
// Errors are exceptions: every failing call throws tessera::Error, which carries the
// TesseraStatus and the message Tessera gave (the face, edge, option or Vulkan call at fault).
// Exceptions were chosen over expected-style results because a failing Tessera call is rare
// and usually fatal to the frame or the tool that made it, and because constructors (which
// create contexts and surfaces) cannot return results. Destructors never throw: a destroy
// that fails (a handle already destroyed through the C API) is ignored there.
//
// Ownership: a Surface must not outlive its Context's device use (destroy surfaces before
// their context, as declaration order in one scope does); a Surface whose Context was
// destroyed first is harmless: its destroy returns DESTROYED_HANDLE, ignored. In host-owned
// mode a Surface may be destroyed while frames that drew it are in flight (Tessera frees it
// frames_in_flight frames later, see tessera_begin_frame); a Context only after the GPU
// finished every command buffer Tessera recorded into.
#ifndef TESSERA_HPP
#define TESSERA_HPP

#include "tessera.h"

#include <array>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace tessera {

class Error : public std::runtime_error {
public:
    Error(TesseraStatus status, const std::string &message)
        : std::runtime_error(std::string(tessera_status_name(static_cast<uint32_t>(status))) +
                             ": " + message),
          status_(status), message_(message) {}
    TesseraStatus status() const noexcept { return status_; }
    // The message alone, without the status name.
    const std::string &message() const noexcept { return message_; }

private:
    TesseraStatus status_;
    std::string message_;
};

// The last error message of `ctx` (nullptr: of the calling thread).
inline std::string last_error(const TesseraContext *ctx = nullptr) {
    std::string s(tessera_last_error(ctx, nullptr, 0), '\0');
    std::vector<char> buffer(s.size() + 1);
    tessera_last_error(ctx, buffer.data(), buffer.size());
    return std::string(buffer.data());
}

// Throws Error unless `status` is OK, with the message kept for `ctx` (or the thread's).
inline void check(TesseraStatus status, const TesseraContext *ctx = nullptr) {
    if (status != TESSERA_STATUS_OK) {
        throw Error(status, last_error(ctx));
    }
}

inline TesseraSurfaceDesc default_surface_desc() {
    TesseraSurfaceDesc d;
    check(tessera_surface_desc_default(&d));
    return d;
}

inline TesseraFrameDesc default_frame_desc() {
    TesseraFrameDesc d;
    check(tessera_frame_desc_default(&d));
    return d;
}

class Context {
public:
    // A context with Tessera's own device (`device`: as the CLI's --device). The pipeline
    // cache is kept in `pipeline_cache_dir` (nullptr: the user's cache directory) unless
    // `pipeline_cache` is TESSERA_PIPELINE_CACHE_OFF.
    static Context standalone(const char *device = nullptr,
                              TesseraValidation validation = TESSERA_VALIDATION_OFF,
                              TesseraPipelineCache pipeline_cache = TESSERA_PIPELINE_CACHE_DEFAULT,
                              const char *pipeline_cache_dir = nullptr) {
        TesseraStandaloneDesc d{device, validation, pipeline_cache, pipeline_cache_dir};
        TesseraContext *raw = nullptr;
        check(tessera_context_create_standalone(&d, &raw));
        return Context(raw);
    }

    // A context on the host's device; the host keeps every handle in `desc` alive.
    static Context host(const TesseraHostDesc &desc) {
        TesseraContext *raw = nullptr;
        check(tessera_context_create_host(&desc, &raw));
        return Context(raw);
    }

    Context(Context &&o) noexcept : raw_(std::exchange(o.raw_, nullptr)) {}
    Context &operator=(Context &&o) noexcept {
        if (this != &o) {
            reset();
            raw_ = std::exchange(o.raw_, nullptr);
        }
        return *this;
    }
    Context(const Context &) = delete;
    Context &operator=(const Context &) = delete;
    ~Context() { reset(); }

    // Destroys the context now (and its remaining surfaces).
    void reset() noexcept {
        if (raw_ != nullptr) {
            tessera_context_destroy(raw_);
            raw_ = nullptr;
        }
    }

    TesseraContext *get() const noexcept { return raw_; }

    void begin_frame(uint64_t frame_index) { check(tessera_begin_frame(raw_, frame_index), raw_); }

    uint32_t validation_errors() const {
        uint32_t n = 0;
        check(tessera_context_validation_errors(raw_, &n), raw_);
        return n;
    }

private:
    explicit Context(TesseraContext *raw) : raw_(raw) {}
    TesseraContext *raw_ = nullptr;
};

class Surface {
public:
    // Builds from OBJ text; an empty string builds the embedded spot mesh.
    static Surface from_obj(Context &ctx, const std::string &obj,
                            const TesseraSurfaceDesc &desc = default_surface_desc(),
                            const char *name = nullptr) {
        TesseraSurface *raw = nullptr;
        check(tessera_surface_create_obj(ctx.get(), obj.empty() ? nullptr : obj.data(),
                                         obj.size(), name, &desc, &raw),
              ctx.get());
        return Surface(ctx.get(), raw);
    }

    static Surface from_mesh(Context &ctx, const TesseraMeshDesc &mesh,
                             const TesseraSurfaceDesc &desc = default_surface_desc()) {
        TesseraSurface *raw = nullptr;
        check(tessera_surface_create(ctx.get(), &mesh, &desc, &raw), ctx.get());
        return Surface(ctx.get(), raw);
    }

    Surface(Surface &&o) noexcept
        : ctx_(std::exchange(o.ctx_, nullptr)), raw_(std::exchange(o.raw_, nullptr)) {}
    Surface &operator=(Surface &&o) noexcept {
        if (this != &o) {
            reset();
            ctx_ = std::exchange(o.ctx_, nullptr);
            raw_ = std::exchange(o.raw_, nullptr);
        }
        return *this;
    }
    Surface(const Surface &) = delete;
    Surface &operator=(const Surface &) = delete;
    ~Surface() { reset(); }

    void reset() noexcept {
        if (raw_ != nullptr) {
            tessera_surface_destroy(ctx_, raw_);
            raw_ = nullptr;
        }
    }

    TesseraSurface *get() const noexcept { return raw_; }

    // Standalone: one frame as RGBA8, rows top to bottom.
    std::vector<uint8_t> render(const TesseraFrameDesc &frame) {
        std::vector<uint8_t> pixels(size_t(frame.width) * frame.height * 4);
        check(tessera_render(ctx_, raw_, &frame, pixels.data(), pixels.size()), ctx_);
        return pixels;
    }

    // The base positions (x, y, z per vertex): the newest given, else those at creation.
    std::vector<float> positions() const {
        size_t n = 0;
        check(tessera_surface_info(ctx_, raw_, &n, nullptr, nullptr), ctx_);
        std::vector<float> xyz(n * 3);
        check(tessera_surface_positions(ctx_, raw_, xyz.data(), n), ctx_);
        return xyz;
    }

    void update_positions(const std::vector<float> &xyz) {
        check(tessera_surface_update_positions(ctx_, raw_, xyz.data(), xyz.size() / 3), ctx_);
    }

    // The view and projection the standalone camera of `frame` uses for this surface.
    std::pair<std::array<float, 16>, std::array<float, 16>>
    camera(const TesseraFrameDesc &frame) const {
        std::pair<std::array<float, 16>, std::array<float, 16>> m;
        check(tessera_surface_camera(ctx_, raw_, &frame, m.first.data(), m.second.data()), ctx_);
        return m;
    }

    // Host-owned mode.
    void set_frame(const TesseraFrameDesc &frame) {
        check(tessera_surface_set_frame(ctx_, raw_, &frame), ctx_);
    }
    void record_pre_pass(VkCommandBuffer cmd) {
        check(tessera_record_pre_pass(ctx_, raw_, cmd), ctx_);
    }
    void record_draw(VkCommandBuffer cmd, const float view[16], const float proj[16]) {
        check(tessera_record_draw(ctx_, raw_, cmd, view, proj), ctx_);
    }

    // Both modes: captures one frame (see tessera_capture for what a host ensures first),
    // writes the OBJ to `obj_path` unless it is nullptr, and returns the weld and crack
    // report.
    TesseraCaptureReport capture(const TesseraFrameDesc &frame, const char *obj_path = nullptr) {
        TesseraCaptureReport report{};
        check(tessera_capture(ctx_, raw_, &frame, obj_path, &report), ctx_);
        return report;
    }

private:
    Surface(TesseraContext *ctx, TesseraSurface *raw) : ctx_(ctx), raw_(raw) {}
    TesseraContext *ctx_ = nullptr;
    TesseraSurface *raw_ = nullptr;
};

// Exact limit positions, derivatives and normals on the CPU (see tessera_limit_evaluate for
// the (face, u, v) domain, the # p lines of a capture). Immutable: one evaluator may be used
// by any number of threads at once.
class LimitEvaluator {
public:
    // Three doubles per point in each.
    struct Samples {
        std::vector<double> positions, du, dv, normals;
    };

    // The limit surface of `surface` (its scheme, creases and current positions).
    static LimitEvaluator of_surface(const Context &ctx, const Surface &surface) {
        TesseraLimitEvaluator *raw = nullptr;
        check(tessera_limit_evaluator_create(ctx.get(), surface.get(), &raw), ctx.get());
        return LimitEvaluator(raw);
    }

    // The limit surface of a mesh under `scheme` (TESSERA_SCHEME_*), with no device.
    static LimitEvaluator of_mesh(const TesseraMeshDesc &mesh,
                                  TesseraScheme scheme = TESSERA_SCHEME_AUTO) {
        TesseraLimitEvaluator *raw = nullptr;
        check(tessera_limit_evaluator_create_mesh(&mesh, scheme, &raw));
        return LimitEvaluator(raw);
    }

    LimitEvaluator(LimitEvaluator &&o) noexcept : raw_(std::exchange(o.raw_, nullptr)) {}
    LimitEvaluator &operator=(LimitEvaluator &&o) noexcept {
        if (this != &o) {
            reset();
            raw_ = std::exchange(o.raw_, nullptr);
        }
        return *this;
    }
    LimitEvaluator(const LimitEvaluator &) = delete;
    LimitEvaluator &operator=(const LimitEvaluator &) = delete;
    ~LimitEvaluator() { reset(); }

    void reset() noexcept {
        if (raw_ != nullptr) {
            tessera_limit_evaluator_destroy(raw_);
            raw_ = nullptr;
        }
    }

    TesseraLimitEvaluator *get() const noexcept { return raw_; }

    size_t face_count() const {
        size_t n = 0;
        check(tessera_limit_evaluator_info(raw_, &n, nullptr));
        return n;
    }

    // Point i is faces[i] at (uvs[2i], uvs[2i+1]). Throws Error naming the first bad point.
    Samples evaluate(const std::vector<uint32_t> &faces, const std::vector<double> &uvs) const {
        if (uvs.size() != 2 * faces.size()) {
            throw Error(TESSERA_STATUS_WRONG_SIZE, "uvs must hold two values per face index");
        }
        Samples s;
        const size_t n = faces.size();
        s.positions.resize(3 * n);
        s.du.resize(3 * n);
        s.dv.resize(3 * n);
        s.normals.resize(3 * n);
        check(tessera_limit_evaluate(raw_, faces.data(), uvs.data(), n, s.positions.data(),
                                     s.du.data(), s.dv.data(), s.normals.data()));
        return s;
    }

private:
    explicit LimitEvaluator(TesseraLimitEvaluator *raw) : raw_(raw) {}
    TesseraLimitEvaluator *raw_ = nullptr;
};

} // namespace tessera

#endif
