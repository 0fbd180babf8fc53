// `grid`: a uniform voxel grid per mesh (and one over the scene's spheres), traversed by 3D-DDA
// (Amanatides & Woo 1987).
#pragma once

#include <cstddef>
#include <memory>

#include "accel/accelerator.h"

namespace whitted {

/// Settings of the `grid` backend. The resolution along each axis is
///   n_axis = extent_axis * cbrt(lambda * N / V)
/// for N triangles in a box of volume V (Cleary & Wyvill 1988; pbrt-v1 uses the same rule), so a
/// cell holds about lambda triangle references; flat axes get one cell.
struct GridConfig {
    float lambda = 4.f;              ///< target triangles per cell (3..5 is the usual sweet spot)
    int max_resolution = 512;        ///< cap on cells per axis
    size_t max_cells = size_t(1) << 24;  ///< cap on the total cells (16M cells = 64 MB of offsets)
};

/// Two-level grid: a grid per mesh, a SAH BVH over the instances, and one world-space grid over
/// the spheres (a sphere is entered into the cells its surface passes through).
std::unique_ptr<Accelerator> create_grid_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                     const GridConfig& config);

}  // namespace whitted
