// The pixel layer: the camera samples of a tile turned into film pixels under one anti-aliasing
// mode (center, stratified, corners, Whitted's adaptive subdivision), tracing every sample that
// neighbouring pixels share (the corner lattice, adaptive edge points) exactly once per sampler,
// also across tiles (docs/antialiasing.md). Each pixel is reduced from its samples in a fixed
// order, so the image does not depend on tile size, thread count or the order tiles run in.
#pragma once

#include <cstdint>
#include <memory>

#include "film/film.h"
#include "integrator/aa_sampler.h"
#include "integrator/camera.h"
#include "integrator/whitted_integrator.h"

namespace whitted {

class PixelSampler {
public:
    /// Samples for the tiles of `window` (of a full_width-pixel-wide image) through `camera` and
    /// `integrator`, scaled by `exposure`, with the AOVs `aovs`; `workers` threads may call
    /// render_tile at once (worker ids 0 .. workers - 1).
    PixelSampler(const CameraModel& camera, const WhittedIntegrator& integrator, const PixelWindow& window,
                 int full_width, const AovSet& aovs, const AaSettings& aa, float exposure, int workers);
    ~PixelSampler();

    /// Every pixel of `tile` (inside the window) into `out` (whose window holds the tile), on worker
    /// `worker` (no two concurrent calls with the same id). Samples the tile shares with tiles
    /// rendered before or at the same time by this sampler are traced once: the first tile to claim
    /// a lattice corner traces it and the others wait for it; adaptive edge points on tile borders
    /// go through a shared table. Tiles may run in any order, each at most once.
    void render_tile(const TileRect& tile, int worker, RayCounters& rays, Film& out);

    /// Samples that were NaN or infinite and were set to 0.
    uint64_t nonfinite() const;
    /// Adaptive: pixels whose square was split at least once.
    uint64_t subdivided() const;

private:
    class Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace whitted
