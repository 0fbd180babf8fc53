#include "renderer/integrator/render.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_scheduler_observer.h>
#include <unistd.h>
#include <xmmintrin.h>
#include <pmmintrin.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <sstream>

#include "renderer/core/error.h"
#include "renderer/core/log.h"

namespace whitted {

namespace {

using Clock = std::chrono::steady_clock;

void set_ftz_daz() {
    // Embree expects flush-to-zero and denormals-are-zero in every thread that traces.
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

/// Sets FTZ/DAZ in every worker thread that enters the arena.
class FtzObserver final : public tbb::task_scheduler_observer {
public:
    explicit FtzObserver(tbb::task_arena& arena) : tbb::task_scheduler_observer(arena) { observe(true); }
    ~FtzObserver() override { observe(false); }
    void on_scheduler_entry(bool) override { set_ftz_daz(); }
};

/// Progress bar with ETA on stderr, redrawn at most every 200 ms by whichever worker gets there.
class ProgressBar {
public:
    ProgressBar(size_t total, bool enabled) : m_total(total), m_enabled(enabled && isatty(STDERR_FILENO)) {}
    void advance() {
        size_t done = ++m_done;
        if (!m_enabled) return;
        std::unique_lock lock(m_mutex, std::try_to_lock);
        if (!lock.owns_lock()) return;
        auto now = Clock::now();
        if (done != m_total && now - m_last < std::chrono::milliseconds(200)) return;
        m_last = now;
        draw(done, now);
    }
    void finish() {
        if (!m_enabled) return;
        std::lock_guard lock(m_mutex);
        draw(m_total, Clock::now());
        std::fputc('\n', stderr);
    }

private:
    void draw(size_t done, Clock::time_point now) {
        const double f = m_total ? double(done) / double(m_total) : 1.0;
        const double elapsed = std::chrono::duration<double>(now - m_start).count();
        const double eta = f > 0 ? elapsed * (1.0 - f) / f : 0.0;
        constexpr int kWidth = 40;
        const int filled = int(f * kWidth);
        std::string bar(size_t(filled), '=');
        bar.resize(kWidth, ' ');
        std::fprintf(stderr, "\r[%s] %3d%%  %6.1fs  ETA %6.1fs", bar.c_str(), int(f * 100.0), elapsed, eta);
        std::fflush(stderr);
    }
    size_t m_total;
    bool m_enabled;
    std::atomic<size_t> m_done{0};
    std::mutex m_mutex;
    Clock::time_point m_start = Clock::now();
    Clock::time_point m_last{};
};

}  // namespace

PixelWindow parse_crop(const std::string& text) {
    PixelWindow w;
    char c1 = 0, c2 = 0, c3 = 0;
    std::istringstream in(text);
    if (!(in >> w.x0 >> c1 >> w.y0 >> c2 >> w.x1 >> c3 >> w.y1) || c1 != ',' || c2 != ',' || c3 != ',' ||
        !(in >> std::ws).eof())
        throw Error(fmt::format("--crop: expected x0,y0,x1,y1 in pixels, got '{}'", text));
    return w;
}

Renderer::Renderer(const Scene& scene, const RenderSettings& settings)
    : m_scene(scene), m_settings(settings), m_view(scene, settings.mapping) {
    if (scene.cameras.empty()) throw Error("the scene has no camera");
    if (settings.camera < 0 || size_t(settings.camera) >= scene.cameras.size())
        throw Error(fmt::format("--camera {}: the scene has {} camera(s), valid indices are 0..{}", settings.camera,
                                scene.cameras.size(), scene.cameras.size() - 1));
    if (settings.tile_size < 1) throw Error(fmt::format("tile size must be at least 1 (got {})", settings.tile_size));
    if (settings.integrator.max_depth < 0)
        throw Error(fmt::format("--max-depth must be >= 0 (got {})", settings.integrator.max_depth));
    m_size = resolve_image_size(scene.cameras[size_t(settings.camera)], settings.width, settings.height);
    constexpr int kMaxDim = 1 << 15;
    if (m_size.width > kMaxDim || m_size.height > kMaxDim)
        throw Error(fmt::format("image size {}x{} exceeds the limit of {} pixels per side", m_size.width,
                                m_size.height, kMaxDim));
    m_window = settings.crop.value_or(PixelWindow{0, 0, m_size.width, m_size.height});
    if (m_window.x0 < 0 || m_window.y0 < 0 || m_window.x1 > m_size.width || m_window.y1 > m_size.height ||
        m_window.width() <= 0 || m_window.height() <= 0)
        throw Error(fmt::format("--crop {},{},{},{} is not a non-empty region inside the {}x{} image", m_window.x0,
                                m_window.y0, m_window.x1, m_window.y1, m_size.width, m_size.height));

    set_ftz_daz();
    auto start = Clock::now();
    m_accel = create_accelerator(settings.accel, scene, m_view, AccelConfig{settings.robust, settings.threads});
    m_build_seconds = std::chrono::duration<double>(Clock::now() - start).count();
}

Renderer::~Renderer() = default;

Film Renderer::render(RenderStats* stats) const {
    const Camera& cam = m_scene.cameras[size_t(m_settings.camera)];
    const CameraModel camera(cam, m_size.width, m_size.height);
    const WhittedIntegrator integrator(m_view, *m_accel, m_settings.integrator);
    Film film(m_size.width, m_size.height, m_window, m_settings.aovs);

    // Tiles in row-major order over the window.
    const int ts = m_settings.tile_size;
    const int tiles_x = (m_window.width() + ts - 1) / ts;
    const int tiles_y = (m_window.height() + ts - 1) / ts;
    const size_t tile_count = size_t(tiles_x) * size_t(tiles_y);

    tbb::enumerable_thread_specific<RayCounters> counters;
    std::atomic<uint64_t> nonfinite{0};
    ProgressBar progress(tile_count, m_settings.progress);

    const int threads = m_settings.threads > 0 ? m_settings.threads : tbb::this_task_arena::max_concurrency();
    tbb::task_arena arena(threads);
    FtzObserver observer(arena);
    set_ftz_daz();

    auto start = Clock::now();
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, tile_count, 1), [&](const tbb::blocked_range<size_t>& range) {
            RayCounters& rc = counters.local();
            for (size_t tile = range.begin(); tile != range.end(); ++tile) {
                const int tx = int(tile % size_t(tiles_x)), ty = int(tile / size_t(tiles_x));
                const int x0 = m_window.x0 + tx * ts, y0 = m_window.y0 + ty * ts;
                const int x1 = std::min(x0 + ts, m_window.x1), y1 = std::min(y0 + ts, m_window.y1);
                for (int y = y0; y < y1; ++y) {
                    for (int x = x0; x < x1; ++x) {
                        // One camera ray through the pixel centre (anti-aliasing modes come later).
                        const Ray ray = camera.generate(x + 0.5, y + 0.5);
                        PrimaryInfo info;
                        Color c = integrator.trace(ray, RayKind::Camera, 0, rc, film.aovs.any() ? &info : nullptr);
                        c *= m_settings.exposure;
                        if (!is_finite(c)) {
                            ++nonfinite;
                            c = Color(0.f);
                        }
                        const size_t i = film.index(x, y);
                        film.beauty[i] = c;
                        if (film.aovs.depth) film.depth[i] = info.depth;
                        if (film.aovs.normal) film.normal[i] = info.normal;
                        if (film.aovs.albedo) film.albedo[i] = info.albedo;
                        if (film.aovs.prim_id) film.prim_id[i] = info.prim;
                        if (film.aovs.inst_id) film.inst_id[i] = info.inst;
                    }
                }
                progress.advance();
            }
        });
    });
    progress.finish();

    if (stats) {
        stats->build_seconds = m_build_seconds;
        stats->render_seconds = std::chrono::duration<double>(Clock::now() - start).count();
        stats->rays = RayCounters{};
        for (const RayCounters& rc : counters) stats->rays += rc;
        stats->nonfinite_samples = nonfinite.load();
        stats->threads = threads;
    }
    if (nonfinite.load() > 0) log_warning("{} samples were not finite and were set to 0", nonfinite.load());
    return film;
}

}  // namespace whitted
