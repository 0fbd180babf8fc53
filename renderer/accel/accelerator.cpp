#include "renderer/accel/accelerator.h"

#include "renderer/accel/embree/embree_accel.h"
#include "renderer/core/error.h"

namespace whitted {

std::unique_ptr<Accelerator> create_accelerator(const std::string& name, const Scene& scene,
                                                const SurfaceFilter& filter, const AccelConfig& config) {
    if (name == "embree") return create_embree_accelerator(scene, filter, EmbreeConfig{config.robust, config.threads});
    throw Error(fmt::format("unknown accelerator '{}' (available: embree)", name));
}

}  // namespace whitted
