// Embree 3 backend: the production path.
#pragma once

#include <cstddef>
#include <memory>

#include "accel/accelerator.h"

namespace whitted {

/// Settings of the Embree backend. Build quality is pinned to MEDIUM: HIGH uses spatial splits,
/// whose build is not deterministic, and the image must not depend on the thread count.
struct EmbreeConfig {
    bool robust = false;   ///< RTC_SCENE_FLAG_ROBUST: slower traversal that avoids some edge misses
    int threads = 0;       ///< build threads, 0 = all
    int packet_width = 4;  ///< batch closest-hit queries: rays per rtcIntersect4/8/16 packet, 1 = rtcIntersect1 each
    int shadow_packet_width = 16;  ///< batch shadow queries: rays per rtcOccluded4/8/16 packet, 1 = rtcOccluded1 each
    bool compact = false;  ///< RTC_SCENE_FLAG_COMPACT: leaves index the vertices instead of copying them
                           ///< (less memory, slower camera rays; docs/performance.md)
    /// A mesh that one instance alone uses (with a transform that keeps orientation) goes into the
    /// top-level scene in world space, so one BVH holds all such meshes' triangles instead of a
    /// BVH of instances over overlapping bounds; meshes used more than once stay instanced
    /// (docs/accelerators.md "Instances"). `embree:flatten=0`: every mesh instanced.
    bool flatten = true;
};

/// Ceiling on the bytes all Embree devices may hold at once (enforced by the device memory
/// monitor; exceeding it is a whitted::Error). Default 8 GiB, the CLI sets --max-memory.
void set_embree_memory_limit(size_t bytes);

/// Builds Embree scenes for `scene` (one triangle scene per mesh, one instance per Instance).
/// Throws whitted::Error when Embree reports an error (the device callback routes to it).
std::unique_ptr<Accelerator> create_embree_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                       const EmbreeConfig& config);

}  // namespace whitted
