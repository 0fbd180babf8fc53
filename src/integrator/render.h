// Renderer: builds the accelerator for a scene once and renders it tile by tile on worker threads
// (src/core/parallel.h) through the pixel layer (pixel_sampler.h). The image is
// bit-identical whatever the thread count or tile size: every sample's radiance is a pure
// function of its image position, and each pixel is reduced from its samples in a fixed order.
#pragma once

#include <cstddef>
#include <functional>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "accel/accelerator.h"
#include "film/film.h"
#include "integrator/aa_sampler.h"
#include "integrator/camera.h"
#include "integrator/render_settings.h"
#include "integrator/scene_view.h"
#include "integrator/whitted_integrator.h"

namespace whitted {

/// Deepest ray tree a render accepts: the recursion uses the stack (about 1 KB per level), and
/// 1024 levels stay far inside an 8 MB thread stack (depth 30000 overflowed it).
constexpr int kMaxTreeDepth = 1024;

struct RenderStats {
    double build_seconds = 0.0;           ///< scene view (analysis, environment map) and accelerator build
    double render_seconds = 0.0;          ///< tracing all tiles
    RayCounters rays;
    uint64_t nonfinite_samples = 0;       ///< samples that were NaN/inf and were replaced by 0
    uint64_t pixels = 0;                  ///< pixels rendered (the window)
    uint64_t pixels_subdivided = 0;       ///< adaptive: pixels whose square was split at least once
    int threads = 0;                      ///< worker threads used

    /// Adds the work of another part of the frame (tiles rendered elsewhere: another thread or rank):
    /// its rays, repaired samples, pixels and threads.
    RenderStats& add(const RenderStats& o) {
        rays += o.rays;
        nonfinite_samples += o.nonfinite_samples;
        pixels += o.pixels;
        pixels_subdivided += o.pixels_subdivided;
        threads += o.threads;
        return *this;
    }
};

/// render_tiles(): the next tile to render (an index into Renderer::tiles()), or nothing when no
/// more should start (all handed out, an interrupt, a distributed job's end).
using NextTile = std::function<std::optional<size_t>()>;
/// render_tiles(): one finished tile, its film's window the tile.
using TileDone = std::function<void(size_t tile, Film&& film)>;

class Renderer {
public:
    /// Validates the settings against the scene (camera index, crop, sizes) and builds the
    /// accelerator; throws whitted::Error on bad settings.
    Renderer(const Scene& scene, const RenderSettings& settings);
    ~Renderer();

    /// What update() did.
    struct Update {
        bool refit = false;     ///< the accelerator was updated in place (else built anew, or untouched)
        double seconds = 0.0;   ///< the view and the accelerator brought up to date
    };
    /// Brings the renderer up to date after its scene changed in place as `update` says (the next
    /// frame of an animation; scene/scene_update.h): the view derived again, the accelerator refit
    /// (Accelerator::update) or, where the backend cannot, built anew. Renders are then those of a
    /// new Renderer over the changed scene. A reloaded scene needs a new Renderer (throws). The
    /// update's time becomes the next renders' build time (RenderStats::build_seconds).
    Update update(const SceneUpdate& update);

    /// Renders the (cropped) image with the settings' anti-aliasing: render_tiles over every tile
    /// in row-major order, pasted into one film. Safe to call repeatedly.
    Film render(RenderStats* stats = nullptr) const;
    /// Renders with another anti-aliasing setting (benchmarks sweep settings on one accelerator).
    /// Throws whitted::Error when `aa` is out of range.
    Film render(const AaSettings& aa, RenderStats* stats = nullptr) const;
    /// Renders with other integrator settings (depth, min_weight, specialize...) on the same
    /// accelerator and tracing every ray through `accel` (e.g. a decorator of accelerator() that
    /// records rays; it must answer for this renderer's scene and view). Benchmarks only.
    Film render(const AaSettings& aa, const IntegratorSettings& integrator, const Accelerator& accel,
                RenderStats* stats = nullptr) const;
    /// The window (the image, or the crop) cut into square tiles of RenderSettings::tile_size
    /// pixels, row-major: the tiles render_tiles() numbers.
    std::vector<TileRect> tiles() const;
    /// The one frame path every caller takes (render(), render_frame, MPI ranks, tile jobs): renders
    /// the tiles `next` hands out on the worker threads, each completely on one worker. Samples that
    /// neighbouring tiles share (the corner lattice, adaptive edge points) are traced once in this
    /// call, so a tile's pixels are bit-identical to the same pixels of render(), whatever renders
    /// which tile where (threads, processes, hosts). `next` and `done` are called from worker
    /// threads, never two at once; a tile whose `next` returned starts, and `done` gets it (its
    /// film's window the tile) when it is finished. Returns when every started tile is done.
    /// Counters add into `stats` (stats->pixels counts the tiles rendered here).
    void render_tiles(const NextTile& next, const TileDone& done, RenderStats* stats = nullptr) const;
    /// An estimate of each tile's cost (of tiles()), for handing out the expensive ones first: the
    /// mean rays of `probes` x `probes` ray trees (at the centres of a grid over the tile, traced
    /// like camera rays) times the samples the tile will take (its pixels, and with adaptive
    /// anti-aliasing the extra samples of the edges the probes see). Deterministic; changes no
    /// image. About 1/64 of a one-sample render at 4 probes per 32-pixel tile.
    std::vector<double> tile_costs(int probes = 4) const;
    /// The shading kernel render() uses (select_kernel on the scene analysis and the settings).
    KernelFeatures kernel() const { return select_kernel(m_view.analysis().features, m_settings.integrator); }

    ImageSize image_size() const { return m_size; }
    /// The rendered region: the whole image, or the crop.
    PixelWindow window() const { return m_window; }
    const RenderSettings& settings() const { return m_settings; }
    const Accelerator& accelerator() const { return *m_accel; }
    const SceneView& view() const { return m_view; }
    double build_seconds() const { return m_build_seconds; }

private:
    /// render_tiles with the given anti-aliasing, integrator settings and accelerator; sets `stats`.
    void trace_tiles(const AaSettings& aa, const IntegratorSettings& integrator, const Accelerator& accel,
                     const NextTile& next, const TileDone& done, RenderStats& stats) const;

    const Scene& m_scene;
    RenderSettings m_settings;
    ImageSize m_size;
    PixelWindow m_window;
    /// When construction began (before m_view: the environment map's build counts as build time).
    std::chrono::steady_clock::time_point m_started = std::chrono::steady_clock::now();
    SceneView m_view;
    std::unique_ptr<Accelerator> m_accel;
    double m_build_seconds = 0.0;
};

/// Parses "x0,y0,x1,y1" (pixels, x1/y1 exclusive); throws whitted::Error when malformed.
PixelWindow parse_crop(const std::string& text);

}  // namespace whitted
