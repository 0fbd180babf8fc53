#include "integrator/render.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <sstream>
#include <vector>

#include "accel/factory/create_accelerator.h"
#include "core/error.h"
#include "core/fp_mode.h"
#include "core/log.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "integrator/pixel_sampler.h"

namespace whitted {

namespace {

using Clock = std::chrono::steady_clock;

/// One worker's ray counters, on their own cache lines (they change at every ray).
struct alignas(64) WorkerRays {
    RayCounters value;
};

/// The window cut into square tiles of `size` pixels, row-major.
std::vector<TileRect> tile_grid(const PixelWindow& w, int size) {
    std::vector<TileRect> tiles;
    for (int y = w.y0; y < w.y1; y += size)
        for (int x = w.x0; x < w.x1; x += size)
            tiles.push_back({x, y, std::min(x + size, w.x1), std::min(y + size, w.y1)});
    return tiles;
}

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
    if (settings.integrator.max_depth < 0 || settings.integrator.max_depth > kMaxTreeDepth)
        throw Error(fmt::format("--max-depth must be in 0..{} (got {})", kMaxTreeDepth, settings.integrator.max_depth));
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

    validate_aa_settings(settings.aa);

    auto start = Clock::now();
    {
        const ScopedFlushDenormals ftz;  // the build in the tracing mode, the caller's mode after it
        m_accel = create_accelerator(settings.accel, scene, m_view, AccelConfig{settings.robust, settings.threads});
    }
    const double accel_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    m_build_seconds = std::chrono::duration<double>(Clock::now() - m_started).count();
    const AccelStats as = m_accel->stats();
    const size_t primitives = scene.instanced_triangle_count() + scene.spheres.size() + scene.quadrics.size();
    log_info("accelerator: {}{}, built in {:.3f}s, {:.1f} MiB ({:.1f} B per primitive)", m_accel->name(),
             m_accel->name() == "embree" ? (settings.robust ? " (robust)" : " (not robust: --no-robust)") : "",
             accel_seconds, double(as.bytes) / double(1 << 20),
             primitives ? double(as.bytes) / double(primitives) : 0.0);
}

Renderer::~Renderer() = default;

Renderer::Update Renderer::update(const SceneUpdate& update) {
    if (update.reloaded) throw Error("Renderer::update: the scene was loaded again: a new Renderer is needed");
    const auto start = Clock::now();
    Update result;
    const bool same_flags = m_view.update();
    if (update.geometry() || !same_flags) {
        const ScopedFlushDenormals ftz;  // as the build in the constructor
        result.refit = same_flags && m_accel->update(update);
        if (!result.refit)
            m_accel = create_accelerator(m_settings.accel, m_scene, m_view,
                                         AccelConfig{m_settings.robust, m_settings.threads});
    }
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    m_build_seconds = result.seconds;
    return result;
}

Film Renderer::render(RenderStats* stats) const { return render(m_settings.aa, stats); }

Film Renderer::render(const AaSettings& aa, RenderStats* stats) const {
    return render(aa, m_settings.integrator, *m_accel, stats);
}

Film Renderer::render(const AaSettings& aa, const IntegratorSettings& settings, const Accelerator& accel,
                      RenderStats* stats) const {
    // The whole window: the frame's tiles in row-major order, each pasted as it is done.
    const std::vector<TileRect> tiles = this->tiles();
    Film film(m_size.width, m_size.height, m_window, m_settings.aovs);
    ProgressBar progress(tiles.size(), m_settings.progress);
    size_t cursor = 0;
    RenderStats frame;
    trace_tiles(
        aa, settings, accel, [&]() -> std::optional<size_t> {
            if (cursor == tiles.size()) return std::nullopt;
            return cursor++;
        },
        [&](size_t, Film&& tile) {
            film.paste(tile);
            progress.advance();
        },
        frame);
    progress.finish();
    if (stats) *stats = frame;
    return film;
}

std::vector<TileRect> Renderer::tiles() const { return tile_grid(m_window, m_settings.tile_size); }

void Renderer::render_tiles(const NextTile& next, const TileDone& done, RenderStats* stats) const {
    RenderStats part;
    trace_tiles(m_settings.aa, m_settings.integrator, *m_accel, next, done, part);
    if (!stats) return;
    stats->build_seconds = part.build_seconds;
    stats->render_seconds += part.render_seconds;
    stats->add(part);
    stats->threads = part.threads;
}

void Renderer::trace_tiles(const AaSettings& aa, const IntegratorSettings& settings, const Accelerator& accel,
                           const NextTile& next, const TileDone& done, RenderStats& stats) const {
    validate_aa_settings(aa);
    if (settings.max_depth < 0 || settings.max_depth > kMaxTreeDepth)
        throw Error(fmt::format("--max-depth must be in 0..{} (got {})", kMaxTreeDepth, settings.max_depth));
    const CameraModel camera(m_scene.cameras[size_t(m_settings.camera)], m_size.width, m_size.height);
    const WhittedIntegrator integrator(m_view, accel, settings);
    const std::vector<TileRect> tiles = this->tiles();
    WorkerPool pool(m_settings.threads);
    // One sampler for every tile this call renders: samples on tile borders are traced once.
    PixelSampler sampler(camera, integrator, m_window, m_size.width, m_settings.aovs, aa, m_settings.exposure,
                         pool.size());
    std::vector<WorkerRays> rays(size_t(pool.size()));
    std::mutex handing;  // next() and done(), one at a time
    uint64_t repaired = 0, pixels = 0;
    const auto start = Clock::now();
    // One iteration per tile at most: each asks `next` for its tile, so they run in its order.
    pool.for_each(tiles.size(), [&](size_t, int worker) {
        std::optional<size_t> index;
        {
            const std::lock_guard<std::mutex> lock(handing);
            index = next();
        }
        if (!index) return;
        RT_CHECK(*index < tiles.size());
        const TileRect& t = tiles[*index];
        Film film(m_size.width, m_size.height, t, m_settings.aovs);
        sampler.render_tile(t, worker, rays[size_t(worker)].value, film);
        // Last line of defence: no NaN or infinity reaches an output file (AOVs included).
        const size_t bad = film.sanitize_nonfinite();
        const std::lock_guard<std::mutex> lock(handing);
        repaired += bad;
        pixels += uint64_t(t.width()) * uint64_t(t.height());
        done(*index, std::move(film));
    });
    if (sampler.nonfinite() > 0) log_warning("{} samples were not finite and were set to 0", sampler.nonfinite());
    if (repaired > 0) log_warning("{} film values were not finite and were set to 0", repaired);
    stats.build_seconds = m_build_seconds;
    stats.render_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    for (const WorkerRays& r : rays) stats.rays += r.value;
    stats.nonfinite_samples = sampler.nonfinite() + repaired;
    stats.pixels = pixels;
    stats.pixels_subdivided = sampler.subdivided();
    stats.threads = pool.size();
}

std::vector<double> Renderer::tile_costs(int probes) const {
    if (probes < 2) throw Error(fmt::format("tile_costs: {} probes per side (expected at least 2)", probes));
    const CameraModel camera(m_scene.cameras[size_t(m_settings.camera)], m_size.width, m_size.height);
    const WhittedIntegrator integrator(m_view, *m_accel, m_settings.integrator);
    const RayCone cone = camera.pixel_cone();
    const AaSettings& aa = m_settings.aa;
    const std::vector<TileRect> tiles = this->tiles();
    std::vector<double> cost(tiles.size(), 0.0);
    WorkerPool pool(m_settings.threads);
    pool.for_each(tiles.size(), [&](size_t i, int) {
        const TileRect& t = tiles[i];
        RayCounters counters;
        std::vector<Color> seen(size_t(probes * probes));
        for (int py = 0; py < probes; ++py)
            for (int px = 0; px < probes; ++px) {
                const double x = t.x0 + (px + 0.5) * t.width() / probes;
                const double y = t.y0 + (py + 0.5) * t.height() / probes;
                seen[size_t(py * probes + px)] =
                    integrator.trace(camera.generate(x, y), RayKind::Camera, 0, counters, nullptr, cone);
            }
        const double pixels = double(t.width()) * double(t.height());
        double samples = pixels;
        if (aa.mode == AaMode::Adaptive) {
            // Edges subdivide: neighbouring probes that differ as the adaptive test measures say an
            // edge crosses between them, about half a probe spacing of pixels per pair, each pixel on
            // an edge adding about 3 * 2^depth samples (the sub-squares along the edge, level by level).
            auto differ = [&](const Color& a, const Color& b) {
                const float e = m_settings.exposure;
                return aa.threshold < 0.f || aa_contrast(a * e, b * e, a * e, b * e) > aa.threshold;
            };
            int edges = 0;
            for (int py = 0; py < probes; ++py)
                for (int px = 0; px < probes; ++px) {
                    const Color& c = seen[size_t(py * probes + px)];
                    if (px + 1 < probes && differ(c, seen[size_t(py * probes + px + 1)])) ++edges;
                    if (py + 1 < probes && differ(c, seen[size_t((py + 1) * probes + px)])) ++edges;
                }
            const double spacing = 0.5 * double(t.width() + t.height()) / probes;
            const double subdivided = std::min(pixels, 0.5 * spacing * edges);
            samples += subdivided * 3.0 * double(1 << aa.depth);
        }
        cost[i] = double(counters.total()) / double(probes * probes) * samples;
    });
    return cost;
}

}  // namespace whitted
