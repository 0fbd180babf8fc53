#include "accel/accelerator.h"

#include "core/error.h"

namespace whitted {

void Accelerator::intersect(std::span<const Ray> rays, RayKind kind, std::span<Hit> hits) const {
    RT_CHECK_EQ(rays.size(), hits.size());
    for (size_t i = 0; i < rays.size(); ++i) hits[i] = intersect(rays[i], kind);
}

void Accelerator::transmittance(std::span<const Ray> rays, std::span<Color> out) const {
    RT_CHECK_EQ(rays.size(), out.size());
    for (size_t i = 0; i < rays.size(); ++i) out[i] = transmittance(rays[i]);
}

}  // namespace whitted
