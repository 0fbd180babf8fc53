// Coincident faces the closest-hit query cannot tell apart: where two non-thin dielectrics touch
// (DielectricContacts) and where an opaque surface lies under a transmissive one
// (OpaqueCovers). Both are small in-house BVHs over just the objects concerned, built only for
// scenes that have such pairs and probed along the normal of a hit (docs/numerical-stability.md,
// "Touching dielectrics" and "Opaque surfaces under transparent ones").
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "accel/accelerator.h"
#include "core/ray_offset.h"
#include "integrator/ray_counters.h"
#include "integrator/scene_view.h"
#include "scene/scene.h"

namespace whitted {

/// A small BVH over some of the scene's objects, probed along the normal of a hit on a candidate
/// object, with hits reported in the scene's ids. The derived class's filter decides which faces
/// count.
class ContactSearch : public SurfaceFilter {
public:
    /// True when hits on object `o` (object_index) look for a coinciding face.
    bool candidate(uint32_t o) const { return m_candidate[o] != 0; }

    Color transmittance(const Ray&, const Hit&) const override { return Color(0.f); }  // never asked

protected:
    /// Hits on the objects flagged in `candidate` (per object_index) will probe a structure over
    /// the objects flagged in `keep`.
    void build(const Scene& scene, std::vector<uint8_t> candidate, const std::vector<uint8_t>& keep);

    /// The nearest accepted face on `probe` (set here: from `reach` behind p along the unit normal
    /// n, 2 reach long) in the scene's ids, or an invalid Hit.
    Hit probe_at(const Vec3f& p, const Vec3f& n, float reach, Ray& probe) const;

    Scene m_sub;                          ///< the objects probed (positions and indices only)

private:
    std::vector<uint32_t> m_geom;         ///< scene geometry id per m_sub geometry id
    std::vector<uint32_t> m_inst;         ///< scene instance per m_sub instance
    std::vector<uint8_t> m_candidate;     ///< per scene object (object_index)
    std::unique_ptr<Accelerator> m_accel; ///< "bvh" over m_sub, with the derived filter
};

/// Two dielectrics sharing a face meet there with coincident, opposite-facing surfaces; the
/// accelerator reports one of them and the refracted ray, offset past the shared plane, never
/// meets the other. A probe leaving the surface hit along its outward normal sees that surface
/// from behind and the other medium's face from the front, so this structure accepts front faces
/// only. The integrator then crosses both faces as one interface (the limit of a vanishing gap).
class DielectricContacts final : public ContactSearch {
public:
    /// The surface of another medium found at a hit point, in the scene's ids.
    struct Contact {
        Hit hit;        ///< on the other medium's surface
        Ray probe;      ///< the query that found it (for SceneView::surface)
    };

    /// Null when no two non-thin dielectric objects of the scene can touch.
    static std::shared_ptr<const DielectricContacts> find(const SceneView& view);

    /// The front face of another non-thin dielectric within guaranteed_gap(p, scale) of p (scale:
    /// the hit's SurfacePoint::offset_scale), probed along the hit's outward unit normal.
    std::optional<Contact> at(const Vec3f& p, float scale, const Vec3f& outward) const {
        Contact c;
        c.hit = probe_at(p, outward, guaranteed_gap(p, scale), c.probe);
        if (!c.hit.valid()) return std::nullopt;
        return c;
    }

    /// SurfaceFilter: front faces only, by SceneView's winding rule.
    bool accept(const Ray& ray, const Hit& hit, RayKind) const override;
    uint32_t mesh_flags(uint32_t) const override { return kNeedsAccept; }
};

/// A transmissive object resting on an opaque one (a thin glass box or a solid glass slab on a
/// floor) has a face in the floor's plane, and the accelerator reports either as rounding decides.
/// The rule that does not depend on the tie: the opaque surface covers the transparent face lying
/// on it.
class OpaqueCovers final : public ContactSearch {
public:
    /// Null when no transmissive object can touch an opaque one.
    static std::shared_ptr<const OpaqueCovers> find(const SceneView& view);

    /// The opaque surface within guaranteed_gap(p, scale) of p on either side of the surface hit
    /// (unit normal n), in the scene's ids (t along the probe), or an invalid Hit. No probe is
    /// traced when p is beyond that reach from the bounds of every opaque object kept.
    Hit at(const Vec3f& p, float scale, const Vec3f& n, RayCounters& counters) const {
        const float reach = guaranteed_gap(p, scale);
        for (int k = 0; k < 3; ++k)
            if (double(p[k]) < m_bounds.lo[k] - double(reach) || double(p[k]) > m_bounds.hi[k] + double(reach)) return Hit{};
        ++counters.contact_probe;
        Ray probe;
        return probe_at(p, n, reach, probe);
    }

    /// SurfaceFilter: every face of a kept opaque object covers.
    bool accept(const Ray&, const Hit&, RayKind) const override { return true; }
    uint32_t mesh_flags(uint32_t) const override { return 0; }

private:
    Bounds3d m_bounds;  ///< world bounds of the opaque objects kept (planes: infinite)
};

}  // namespace whitted
