// The pixel layer: the camera samples of a tile turned into film pixels under one anti-aliasing
// mode (center, stratified, corners, Whitted's adaptive subdivision), tracing every sample that
// neighbouring pixels share (the corner lattice, adaptive edge points) exactly once
// (docs/antialiasing.md). Each pixel is reduced from its samples in a fixed order, so the image
// does not depend on tile size, thread count or the order tiles run in.
#pragma once

#include <cstdint>
#include <memory>

#include "renderer/film/film.h"
#include "renderer/integrator/aa_sampler.h"
#include "renderer/integrator/camera.h"
#include "renderer/integrator/whitted_integrator.h"

namespace whitted {

class PixelSampler {
public:
    /// Samples for `film` (its window) through `camera` and `integrator`, scaled by `exposure`;
    /// `workers` threads may call render_tile at once (worker ids 0 .. workers - 1).
    PixelSampler(const CameraModel& camera, const WhittedIntegrator& integrator, Film& film, const AaSettings& aa,
                 float exposure, int workers);
    ~PixelSampler();

    /// Passes over all tiles the mode needs: 1, or 2 for corners and adaptive (the shared corner
    /// lattice first, then the pixels from it). Every tile of a pass must finish before the next.
    int passes() const;
    /// Pass `pass` over one tile, on worker `worker` (no two concurrent calls with the same id).
    void render_tile(int pass, const TileRect& tile, int worker, RayCounters& rays);

    /// Samples that were NaN or infinite and were set to 0.
    uint64_t nonfinite() const;
    /// Adaptive: pixels whose square was split at least once.
    uint64_t subdivided() const;

private:
    class Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace whitted
