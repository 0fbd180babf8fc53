// Which shading kernel a render uses: the integrator is compiled once per feature set, and each
// render picks the smallest instantiation its scene needs (docs/integrator.md, "Specialised kernels").
#pragma once

#include <string>

#include "shading/scene_analysis.h"

namespace whitted {

struct IntegratorSettings;

/// The compile-time feature set of a shading kernel (one instantiation per combination used).
struct KernelFeatures {
    bool attributes = true;    ///< UVs, vertex colors, ray-cone footprints, per-hit material evaluation
    bool mirror = true;        ///< reflection rays (also total internal reflection); the environment's
                               ///< glossy term kg G casts no ray and is in every kernel
    bool transmission = true;  ///< refraction, alpha blend, absorption, shadow transmittance products
    bool tables = false;       ///< constant materials from a table, per-object light lists
    bool layers = true;        ///< the layered material extensions (shading/layered_model.h), per material
    constexpr bool operator==(const KernelFeatures&) const = default;
};

/// The kernel that handles every scene: all features, no tables (--no-specialize).
constexpr KernelFeatures kGeneralKernel{};

/// Every kernel select_kernel can return, and the general one: the instantiations compiled.
constexpr KernelFeatures kKernels[] = {
    kGeneralKernel,
    {false, false, false, true, false}, {true, false, false, true, false},  // opaque, no recursion
    {false, true, false, true, false},  {true, true, false, true, false},   // opaque mirrors
    {false, true, true, true, false},   {true, true, true, true, false},    // glass (and mirrors)
    {true, false, false, true, true},   {true, true, false, true, true},    // layered materials
    {true, true, true, true, true},
};

/// The smallest kernel that renders a scene with these features exactly like the general one.
KernelFeatures select_kernel(const SceneFeatures& scene, const IntegratorSettings& settings);

/// "general" or e.g. "specialised: opaque, no recursion, constant materials" (for logs).
std::string kernel_name(const KernelFeatures& k);

}  // namespace whitted
