// The accelerator factory: a backend of accel/ built by name ("embree", "bvh:precision=double",
// ...). It sits above every backend, so the interface (accel/accelerator.h) knows none of them.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "accel/accelerator.h"

namespace whitted {

/// The backend names create_accelerator knows, production default first.
const std::vector<std::string>& accelerator_names();

/// Builds the named backend: "embree", "bvh", "grid", "octree", "kdop" or "brute" (the O(n)
/// oracle), optionally followed by options, e.g. "bvh:precision=double,bv=sphere",
/// "grid:lambda=8" or "embree:packet=8,compact=1" (docs/accelerators.md lists them). Throws
/// whitted::Error naming the valid choices for an unknown name or option. `scene` and `filter`
/// must outlive the accelerator, unchanged: backends may keep references to them (Embree shares
/// the meshes' index arrays).
std::unique_ptr<Accelerator> create_accelerator(const std::string& name, const Scene& scene,
                                                const SurfaceFilter& filter, const AccelConfig& config = {});

/// Ceiling on the bytes accelerator builds may hold at once, all of them together; exceeding it
/// is a whitted::Error. The Embree backend enforces it through its device memory monitor; the
/// in-house backends do not check it. Default 8 GiB; the CLI sets it from --max-memory.
void set_accelerator_memory_limit(size_t bytes);

}  // namespace whitted
