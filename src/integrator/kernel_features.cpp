#include "integrator/kernel_features.h"

#include "integrator/whitted_integrator.h"

namespace whitted {

KernelFeatures select_kernel(const SceneFeatures& scene, const IntegratorSettings& settings) {
    if (!settings.specialize) return kGeneralKernel;
    KernelFeatures k;
    k.tables = true;
    k.attributes = scene.varying;
    k.transmission = !scene.opaque();
    k.mirror = scene.mirror || k.transmission;  // total internal reflection turns kt into kr
    // Layered materials: per-hit evaluation with the texture frame (the analysis' mirror flag
    // covers the coat's own mirror rays).
    k.layers = scene.layered;
    if (k.layers) k.attributes = true;
    return k;
}

std::string kernel_name(const KernelFeatures& k) {
    if (k == kGeneralKernel) return "general";
    std::string s = "specialised:";
    s += k.transmission ? " transmission," : " opaque,";
    s += k.mirror ? (k.transmission ? " reflection+refraction," : " reflection only,") : " no recursion,";
    s += k.attributes ? " textures/vertex colors" : " constant materials (no UVs)";
    if (k.tables) s += ", light culling";
    if (k.layers) s += ", layered materials";
    return s;
}

}  // namespace whitted
