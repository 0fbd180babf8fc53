// Which way a surface faces the ray that hit it, and the secondary rays that leave it: the one
// orientation and offset rule of the integrator and of the stability probes' tracer.
#pragma once

#include "core/vecmath.h"
#include "integrator/scene_view.h"

namespace whitted {

struct ShadingFrame {
    Vec3f V;      ///< unit direction toward the viewer (-ray direction)
    bool front;   ///< the ray hit the front face by winding (decided on the geometric normal): it
                  ///< enters the medium behind the surface; false = it leaves it
    Vec3f Ng;     ///< geometric normal on the viewer's side
    Vec3f N;      ///< shading normal on the viewer's side; Ng where the interpolated normal faces away
};

/// The frame of the hit `sp` seen along unit direction `dir`.
inline ShadingFrame shading_frame(const SurfacePoint& sp, const Vec3f& dir) {
    ShadingFrame f;
    f.V = -dir;
    f.front = dot(sp.ng, f.V) >= 0.f;
    f.Ng = f.front ? sp.ng : -sp.ng;
    f.N = f.front ? sp.ns : -sp.ns;
    if (dot(f.N, f.V) <= 0.f) f.N = f.Ng;  // shading normal facing away from the viewer: fall back
    return f;
}

/// The directions the layered material extensions read (layered_model.h), on the viewer's side:
/// the coat normal turned like N, and N itself where it would face away.
inline LayerFrame layer_frame(const SurfacePoint& sp, const ShadingFrame& f) {
    LayerFrame l{f.V, f.N, f.front ? sp.nc : -sp.nc, sp.tangent, sp.bitangent};
    if (dot(l.Nc, f.V) <= 0.f) l.Nc = f.N;
    return l;
}

/// A secondary ray from sp along unit `dir`, its origin moved to the side `side` points to (+Ng:
/// the viewer's side, -Ng: through the surface) by the accelerator's offset policy.
inline Ray spawn_ray(const RayOffsetPolicy& offset, const SurfacePoint& sp, const Vec3f& side, const Vec3f& dir) {
    Ray r;
    r.org = offset.origin(sp.p, sp.offset_scale, side);
    r.dir = dir;
    return r;
}

}  // namespace whitted
