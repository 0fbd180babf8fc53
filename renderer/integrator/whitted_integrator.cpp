#include "renderer/integrator/whitted_integrator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "renderer/core/error.h"
#include "renderer/core/ray_offset.h"
#include "renderer/core/uninitialized.h"
#include "renderer/integrator/shading_frame.h"
#include "shading/light_sample.h"
#include "shading/optics.h"

namespace whitted {

namespace {

void count(RayCounters& c, RayKind kind) {
    switch (kind) {
        case RayKind::Camera: ++c.camera; break;
        case RayKind::Shadow: ++c.shadow; break;
        case RayKind::Reflection: ++c.reflection; break;
        case RayKind::Refraction: ++c.refraction; break;
    }
}

Color sanitize(const Color& c) {
    return {std::isfinite(c.x) ? c.x : 0.f, std::isfinite(c.y) ? c.y : 0.f, std::isfinite(c.z) ? c.z : 0.f};
}

Color exp_neg(const Color& c) { return {std::exp(-c.x), std::exp(-c.y), std::exp(-c.z)}; }

}  // namespace

KernelFeatures select_kernel(const SceneFeatures& scene, const IntegratorSettings& settings) {
    if (!settings.specialize) return kGeneralKernel;
    KernelFeatures k;
    k.tables = true;
    k.attributes = scene.varying;
    k.transmission = !scene.opaque();
    k.mirror = scene.mirror || k.transmission;  // total internal reflection turns kt into kr
    return k;
}

std::string kernel_name(const KernelFeatures& k) {
    if (k == kGeneralKernel) return "general";
    std::string s = "specialised:";
    s += k.transmission ? " transmission," : " opaque,";
    s += k.mirror ? (k.transmission ? " reflection+refraction," : " reflection only,") : " no recursion,";
    s += k.attributes ? " textures/vertex colors" : " constant materials (no UVs)";
    if (k.tables) s += ", light culling";
    return s;
}

namespace {

/// Every kernel the selection can return, and the general one.
constexpr KernelFeatures kKernels[] = {
    kGeneralKernel,
    {false, false, false, true}, {true, false, false, true},  // opaque, no recursion
    {false, true, false, true},  {true, true, false, true},   // opaque mirrors
    {false, true, true, true},   {true, true, true, true},    // glass (and mirrors)
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Touching dielectrics (docs/numerical-stability.md, StressRefraction.TouchingSlabsActAsOne).
//
// Two dielectrics that share a face meet there with coincident, opposite-facing surfaces. The
// accelerator reports one of the two (both are at the same t, so which one is arbitrary), and the
// refracted ray, moved a few ulps past the shared plane (ray_offset.h), starts inside the second
// medium and never meets its face: it crosses the second medium bent as if it had left into air.
// A closest-hit query cannot list coincident surfaces (ties), but their orientation tells them
// apart: a probe leaving the surface hit along its outward normal sees that surface from behind
// and the face of a medium beginning there from the front. DielectricContacts is a small
// structure over the non-thin dielectrics that may touch another one, queried with a filter that
// accepts front faces only. The two faces are then crossed as one interface with the relative ior
// of the two media: the limit of a vanishing gap (a gap far thinner than a wavelength cannot
// totally reflect: frustrated total internal reflection). pbrt and Mitsuba leave this to the
// scene (one interface with an exterior ior); production renderers ask for overlapping volumes
// with priorities (Schmidt & Budge 2002). A mesh that can only touch itself (two glass parts in
// one mesh) is not a candidate: candidates come from pairs of objects (DielectricContacts::find).

/// What DielectricContacts and OpaqueCovers share: a small in-house BVH over some of the scene's
/// objects (the faces a candidate's surface may coincide with), probed along the normal of a hit
/// on a candidate object, with hits reported in the scene's ids. The derived class's filter
/// decides which faces count.
class ContactSearch : public SurfaceFilter {
public:
    /// True when hits on object `o` (object_index) look for a coinciding face.
    bool candidate(uint32_t o) const { return m_candidate[o] != 0; }

    Color transmittance(const Ray&, const Hit&) const override { return Color(0.f); }  // never asked

protected:
    /// Hits on the objects flagged in `candidate` (per object_index) will probe a structure over
    /// the objects flagged in `keep` (defined below, with the object helpers).
    void build(const Scene& scene, std::vector<uint8_t> candidate, const std::vector<uint8_t>& keep);

    /// The nearest accepted face on `probe` (set here: from `reach` behind p along the unit normal
    /// n, 2 reach long) in the scene's ids, or an invalid Hit.
    Hit probe_at(const Vec3f& p, const Vec3f& n, float reach, Ray& probe) const {
        probe.org = p - n * reach;
        probe.dir = n;
        probe.tfar = 2.f * reach;
        Hit h = m_accel->intersect(probe, RayKind::Refraction);
        if (!h.valid()) return h;
        const bool mesh = h.geom < m_sub.meshes.size();
        h.inst = mesh ? m_inst[h.inst] : kInvalidId;
        h.geom = m_geom[h.geom];
        return h;
    }

    Scene m_sub;                          ///< the objects probed (positions and indices only)

private:
    std::vector<uint32_t> m_geom;         ///< scene geometry id per m_sub geometry id
    std::vector<uint32_t> m_inst;         ///< scene instance per m_sub instance
    std::vector<uint8_t> m_candidate;     ///< per scene object (object_index)
    std::unique_ptr<Accelerator> m_accel; ///< "bvh" over m_sub, with the derived filter
};

class DielectricContacts final : public ContactSearch {
public:
    /// The surface of another medium found at a hit point, in the scene's ids.
    struct Contact {
        Hit hit;        ///< on the other medium's surface
        Ray probe;      ///< the query that found it (for SceneView::surface)
    };

    /// Null when no two non-thin dielectrics of the scene can touch (nothing to look for).
    static std::shared_ptr<const DielectricContacts> find(const SceneView& view);

    /// The front face of another non-thin dielectric within guaranteed_gap(p, scale) of p (scale:
    /// the surface hit's SurfacePoint::offset_scale, the unit secondary rays leave it by), found by
    /// a probe from just inside the surface hit along its outward unit normal. The reach is the
    /// float path's 12 units whatever the main accelerator: at least any RayOffsetPolicy's gap,
    /// so no surface a secondary ray may skip goes unlooked for.
    std::optional<Contact> at(const Vec3f& p, float scale, const Vec3f& outward) const {
        Contact c;
        c.hit = probe_at(p, outward, guaranteed_gap(p, scale), c.probe);
        if (!c.hit.valid()) return std::nullopt;
        return c;
    }

    // SurfaceFilter: front faces only, by the same winding rule as SceneView (ng from the world
    // vertices in double; spheres: outward; planes: `normal`).
    bool accept(const Ray& ray, const Hit& hit, RayKind) const override {
        const Vec3d d(ray.dir);
        switch (m_sub.geom_kind(hit.geom)) {
            case GeomKind::Mesh: {
                Vec3d p[3];
                m_sub.world_triangle(hit.inst, hit.prim, p);
                return dot(cross(p[1] - p[0], p[2] - p[0]), d) < 0.0;
            }
            case GeomKind::Sphere: {
                const Sphere& s = m_sub.spheres[hit.geom - m_sub.meshes.size()];
                return dot(Vec3d(ray.org) + d * double(hit.t) - s.center, d) < 0.0;
            }
            case GeomKind::Plane:
                return dot(m_sub.planes[hit.geom - m_sub.meshes.size() - m_sub.spheres.size()].normal, d) < 0.0;
        }
        return false;
    }
    uint32_t mesh_flags(uint32_t) const override { return kNeedsAccept; }
};

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// One object for the touching tests (DielectricContacts, OpaqueCovers).
struct ContactObject {
    uint32_t object;                      ///< object_index
    GeomKind kind;
    Bounds3d bounds;                      ///< world space (planes: infinite)
    const Sphere* sphere = nullptr;
    const Plane* plane = nullptr;
};

/// Distance within which two surfaces count as touching: twice the probe's reach at magnitude m
/// (float spacing of m times 2 kGuaranteedGapUlps), so rounding of either surface cannot hide a
/// contact the probe would find.
double touch_tolerance(double m) { return 2.0 * double(kGuaranteedGapUlps) * std::max(m, 1e-30) * 0x1p-23; }

double magnitude(const Bounds3d& b) { return std::max(max_abs(b.lo), max_abs(b.hi)); }

/// Signed distances of a box's corners from a plane: [min, max].
std::pair<double, double> plane_extent(const Plane& p, const Bounds3d& b) {
    double lo = kInf, hi = -kInf;
    for (int c = 0; c < 8; ++c) {
        const Vec3d corner{(c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y, (c & 4) ? b.hi.z : b.lo.z};
        const double d = dot(p.normal, corner - p.point);
        lo = std::min(lo, d);
        hi = std::max(hi, d);
    }
    return {lo, hi};
}

/// Whether two objects can share a face: exact for spheres and planes, overlapping bounds
/// (conservative) for meshes.
bool may_touch(const ContactObject& a, const ContactObject& b) {
    if (a.kind == GeomKind::Plane && b.kind == GeomKind::Plane) {
        const double tol = touch_tolerance(std::max(max_abs(a.plane->point), max_abs(b.plane->point)));
        return length(cross(a.plane->normal, b.plane->normal)) <= 1e-6 &&
               std::fabs(dot(a.plane->normal, b.plane->point - a.plane->point)) <= tol;
    }
    if (b.kind == GeomKind::Plane) return may_touch(b, a);
    if (a.kind == GeomKind::Plane) {
        const double tol = touch_tolerance(std::max(magnitude(b.bounds), max_abs(a.plane->point)));
        if (b.kind == GeomKind::Sphere)
            return std::fabs(std::fabs(dot(a.plane->normal, b.sphere->center - a.plane->point)) - b.sphere->radius) <= tol;
        const auto [lo, hi] = plane_extent(*a.plane, b.bounds);
        return lo <= tol && hi >= -tol;
    }
    const double tol = touch_tolerance(std::max(magnitude(a.bounds), magnitude(b.bounds)));
    if (a.kind == GeomKind::Sphere && b.kind == GeomKind::Sphere) {
        // Outside each other (external tangency) or one inside the other (internal tangency).
        const double d = length(a.sphere->center - b.sphere->center);
        const double ra = a.sphere->radius, rb = b.sphere->radius;
        return std::fabs(d - (ra + rb)) <= tol || std::fabs(d - std::fabs(ra - rb)) <= tol;
    }
    for (int k = 0; k < 3; ++k)
        if (a.bounds.lo[k] > b.bounds.hi[k] + tol || b.bounds.lo[k] > a.bounds.hi[k] + tol) return false;
    return true;
}

/// The objects whose material `select` accepts, with world bounds.
template <class Select>
std::vector<ContactObject> contact_objects(const Scene& scene, Select select) {
    std::vector<ContactObject> objects;
    std::vector<Bounds3d> mesh_bounds(scene.meshes.size());
    for (uint32_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        const Mesh& mesh = scene.meshes[inst.mesh];
        if (!select(mesh.material) || mesh.indices.empty()) continue;
        Bounds3d& mb = mesh_bounds[inst.mesh];
        if (mb.empty()) mb = mesh.bounds();
        objects.push_back({object_index(scene, inst.mesh, i), GeomKind::Mesh, transform_bounds(inst.world_from_object, mb)});
    }
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
        const Sphere& s = scene.spheres[i];
        if (!select(s.material)) continue;
        const uint32_t g = scene.sphere_geom_id(i);
        ContactObject o{object_index(scene, g, kInvalidId), GeomKind::Sphere, {}};
        o.bounds.extend(s.center - Vec3d(s.radius));
        o.bounds.extend(s.center + Vec3d(s.radius));
        o.sphere = &s;
        objects.push_back(o);
    }
    for (size_t i = 0; i < scene.planes.size(); ++i) {
        const Plane& p = scene.planes[i];
        if (!select(p.material)) continue;
        ContactObject o{object_index(scene, scene.plane_geom_id(i), kInvalidId), GeomKind::Plane, {}};
        o.bounds = {Vec3d(-kInf), Vec3d(kInf)};
        o.plane = &p;
        objects.push_back(o);
    }
    return objects;
}

/// The objects flagged in `keep` (per object_index) as a scene of their own, geometry only
/// (positions and indices, one material), in scene order; geom and inst receive the scene's
/// geometry id per sub-scene geometry id and the scene's instance per sub-scene instance.
void extract_objects(const Scene& scene, const std::vector<uint8_t>& keep, Scene& sub, std::vector<uint32_t>& geom,
                     std::vector<uint32_t>& inst) {
    sub.materials.resize(1);
    std::vector<uint32_t> sub_mesh(scene.meshes.size(), kInvalidId);
    for (uint32_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& in = scene.instances[i];
        if (!keep[object_index(scene, in.mesh, i)]) continue;
        if (sub_mesh[in.mesh] == kInvalidId) {
            sub_mesh[in.mesh] = uint32_t(sub.meshes.size());
            Mesh m;
            m.name = scene.meshes[in.mesh].name;
            m.positions = scene.meshes[in.mesh].positions;
            m.indices = scene.meshes[in.mesh].indices;
            sub.meshes.push_back(std::move(m));
            geom.push_back(in.mesh);
        }
        Instance si = in;
        si.mesh = sub_mesh[in.mesh];
        sub.instances.push_back(si);
        inst.push_back(i);
    }
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
        const uint32_t g = scene.sphere_geom_id(i);
        if (!keep[object_index(scene, g, kInvalidId)]) continue;
        Sphere s = scene.spheres[i];
        s.material = 0;
        sub.spheres.push_back(s);
        geom.push_back(g);
    }
    for (size_t i = 0; i < scene.planes.size(); ++i) {
        const uint32_t g = scene.plane_geom_id(i);
        if (!keep[object_index(scene, g, kInvalidId)]) continue;
        Plane p = scene.planes[i];
        p.material = 0;
        sub.planes.push_back(p);
        geom.push_back(g);
    }
}

}  // namespace

void ContactSearch::build(const Scene& scene, std::vector<uint8_t> candidate, const std::vector<uint8_t>& keep) {
    m_candidate = std::move(candidate);
    // The kept objects as a scene of their own (geometry only), in scene order, in the in-house
    // BVH: deterministic and watertight (docs/accelerators.md).
    extract_objects(scene, keep, m_sub, m_geom, m_inst);
    m_accel = create_accelerator("bvh", m_sub, *this);
}

std::shared_ptr<const DielectricContacts> DielectricContacts::find(const SceneView& view) {
    const Scene& scene = view.scene();
    const SceneAnalysis& analysis = view.analysis();
    // The non-thin dielectric objects, with world bounds.
    const std::vector<ContactObject> objects = contact_objects(scene, [&](uint32_t material) {
        const MaterialFeatures& mf = analysis.materials[material];
        return mf.transmission && !mf.constant.thin;  // `thin` does not vary over a surface
    });
    // Pairs that may touch (a handful of dielectric objects in practice: quadratic is fine).
    std::vector<uint8_t> candidate(analysis.object_count, 0);
    bool any = false;
    for (size_t a = 0; a < objects.size(); ++a)
        for (size_t b = a + 1; b < objects.size(); ++b)
            if (may_touch(objects[a], objects[b])) {
                candidate[objects[a].object] = candidate[objects[b].object] = 1;
                any = true;
            }
    if (!any) return nullptr;

    // The candidates probe a structure over themselves.
    auto c = std::make_shared<DielectricContacts>();
    c->build(scene, candidate, candidate);
    return c;
}

// ---------------------------------------------------------------------------------------------
// Opaque surfaces under thin transmissive ones (default.glb's red panel: a closed thin-walled box
// standing on the floor; tests/render/test_contact_edges.cpp).
//
// A transparent object resting on an opaque one meets it with coincident faces (the box's bottom
// face lies in the floor's plane). A ray through the transparent object reaches both at the same
// t and the accelerator reports either, as rounding decides: the floor, or the bottom face, whose
// straight-through continuation starts a few ulps past the shared plane and never meets the
// floor (a dotted near-black line along the panel's foot that moved between backends). The
// answer must not depend on the tie, and only one rule can be checked at the transparent hit
// alone: the opaque surface covers the transparent face lying on it (the limit of the object
// lifted off the floor, less the tint of its bottom face). So at a hit on a thin transmissive
// object that can touch an opaque one, a probe along the surface's normal, guaranteed_gap to
// either side (the distance within which a secondary ray may skip a surface), looks for an opaque
// surface, and one found is shaded instead, as the same ray's hit at the same t. Like
// DielectricContacts: a small in-house BVH over just the opaque objects that can touch such an
// object; scenes without a pair build nothing, and the kernels test a null pointer. Non-thin
// dielectrics on an opaque surface (their exit ray and absorption) remain open
// (docs/numerical-stability.md).
class OpaqueCovers final : public ContactSearch {
public:
    /// Null when no thin transmissive object can touch an opaque one. Candidates: the thin
    /// transmissive objects that may touch an opaque object.
    static std::shared_ptr<const OpaqueCovers> find(const SceneView& view);

    /// The opaque surface within guaranteed_gap(p, scale) of p on either side of the surface hit
    /// (unit normal n), in the scene's ids (t along the probe), or an invalid Hit. No probe is
    /// traced when p is farther than that reach from the bounds of every opaque object kept (most
    /// hits on a candidate: a panel standing on the floor touches it along one edge).
    Hit at(const Vec3f& p, float scale, const Vec3f& n, RayCounters& counters) const {
        const float reach = guaranteed_gap(p, scale);
        for (int k = 0; k < 3; ++k)
            if (double(p[k]) < m_bounds.lo[k] - double(reach) || double(p[k]) > m_bounds.hi[k] + double(reach)) return Hit{};
        ++counters.contact_probe;
        Ray probe;
        return probe_at(p, n, reach, probe);
    }

    // SurfaceFilter: every face of an opaque object covers (masked and blended ones are not kept).
    bool accept(const Ray&, const Hit&, RayKind) const override { return true; }
    uint32_t mesh_flags(uint32_t) const override { return 0; }

private:
    Bounds3d m_bounds;  ///< world bounds of the opaque objects kept (planes: infinite)
};

std::shared_ptr<const OpaqueCovers> OpaqueCovers::find(const SceneView& view) {
    const Scene& scene = view.scene();
    const SceneAnalysis& analysis = view.analysis();
    const std::vector<ContactObject> covered = contact_objects(scene, [&](uint32_t material) {
        const MaterialFeatures& mf = analysis.materials[material];
        return mf.transmission && mf.constant.thin;
    });
    if (covered.empty()) return nullptr;
    const std::vector<ContactObject> opaque = contact_objects(scene, [&](uint32_t material) {
        const MaterialFeatures& mf = analysis.materials[material];
        return !mf.transmission && !mf.alpha_blend && !mf.alpha_mask;
    });
    // Pairs that may touch (a handful of transparent objects against the opaque ones).
    auto c = std::make_shared<OpaqueCovers>();
    std::vector<uint8_t> candidate(analysis.object_count, 0), keep(analysis.object_count, 0);
    bool any = false;
    for (const ContactObject& a : covered)
        for (const ContactObject& b : opaque)
            if (may_touch(a, b)) {
                candidate[a.object] = keep[b.object] = 1;
                c->m_bounds.extend(b.bounds);
                any = true;
            }
    if (!any) return nullptr;
    c->build(scene, std::move(candidate), keep);
    return c;
}

WhittedIntegrator::WhittedIntegrator(const SceneView& view, const Accelerator& accel, const IntegratorSettings& settings)
    : m_view(view), m_accel(accel), m_offset(accel.ray_offset()), m_settings(settings),
      m_kernel(select_kernel(view.analysis().features, settings)) {
    // The instantiation for the selected features, chosen once (no per-ray dispatch below).
    auto pick = [&]<size_t... I>(std::index_sequence<I...>) {
        ((m_kernel == kKernels[I] ? (void)(m_trace = kernel_entry<kKernels[I]>(),
                                           m_trace_camera = camera_entry<kKernels[I]>())
                                  : (void)0),
         ...);
    };
    pick(std::make_index_sequence<std::size(kKernels)>{});
    RT_CHECK(m_trace != nullptr);
    if (m_kernel.transmission) {
        m_contacts = DielectricContacts::find(view);
        m_covers = OpaqueCovers::find(view);
    }
}

template <KernelFeatures K>
Color WhittedIntegrator::radiance_of(const Ray& ray, const Hit& hit, int depth, RayCounters& counters,
                                     PrimaryInfo* primary, const RayCone& cone, float weight) const {
    if (!hit.valid()) return m_settings.background;
    return sanitize(shade<K>(ray, hit, depth, counters, primary, cone, weight));
}

template <KernelFeatures K>
Color WhittedIntegrator::trace_kernel(const Ray& ray, RayKind kind, int depth, RayCounters& counters,
                                      PrimaryInfo* primary, const RayCone& cone, float weight) const {
    count(counters, kind);
    return radiance_of<K>(ray, m_accel.intersect(ray, kind), depth, counters, primary, cone, weight);
}

void WhittedIntegrator::trace_camera(std::span<const Ray> rays, std::span<Color> radiance, RayCounters& counters,
                                     const RayCone& cone, std::span<PrimaryInfo> primary) const {
    RT_CHECK(radiance.size() == rays.size());
    if (!primary.empty()) RT_CHECK(primary.size() == rays.size());
    (this->*m_trace_camera)(rays, radiance, counters, cone, primary);
}

template <KernelFeatures K>
void WhittedIntegrator::trace_camera_kernel(std::span<const Ray> rays, std::span<Color> radiance, RayCounters& counters,
                                            const RayCone& cone, std::span<PrimaryInfo> primary) const {
    if constexpr (K == kGeneralKernel) {
        // The general path stays one closest-hit query per ray (the baseline packets are measured
        // against, docs/performance.md).
        for (size_t i = 0; i < rays.size(); ++i)
            radiance[i] = trace_kernel<K>(rays[i], RayKind::Camera, 0, counters, primary.empty() ? nullptr : &primary[i],
                                          cone, 1.f);
    } else {
        // One batch query per chunk (coherent packets in the Embree backend), then the hits are
        // shaded in order exactly as trace_kernel() shades them.
        // Left uninitialised: the batch query writes every record, and filling 64 default Hits
        // per call was two thirds of this function's time on a scene of misses (the Duck).
        UninitializedArray<Hit, kCameraBatch> hits;
        for (size_t begin = 0; begin < rays.size(); begin += kCameraBatch) {
            const size_t n = std::min(kCameraBatch, rays.size() - begin);
            m_accel.intersect(rays.subspan(begin, n), RayKind::Camera, hits.first(n));
            counters.camera += n;
            for (size_t j = 0; j < n; ++j) {
                const size_t i = begin + j;
                radiance[i] = radiance_of<K>(rays[i], hits.at[j], 0, counters, primary.empty() ? nullptr : &primary[i],
                                             cone, 1.f);
            }
        }
    }
}

void WhittedIntegrator::probe(const Ray& ray, RayCounters& counters, PrimaryInfo& primary) const {
    ++counters.aov_probe;
    const Hit hit = m_accel.intersect(ray, RayKind::Camera);
    if (!hit.valid()) return;
    const SurfacePoint sp = m_view.surface(ray, hit);
    const WhittedCoeffs c = m_view.coefficients(sp);
    primary.hit = true;
    primary.depth = hit.t;
    primary.normal = shading_frame(sp, ray.dir).N;  // as shade() reports it
    primary.albedo = c.kd + c.kr + c.kt;
    primary.prim = hit.prim;
    primary.inst = hit.inst;
}

std::optional<WhittedIntegrator::OtherMedium> WhittedIntegrator::other_medium(const Hit& hit, const SurfacePoint& sp,
                                                                               RayCounters& counters) const {
    const Scene& scene = m_view.scene();
    if (!m_contacts->candidate(object_index(scene, hit.geom, hit.inst))) return std::nullopt;
    ++counters.contact_probe;
    const auto contact = m_contacts->at(sp.p, sp.offset_scale, sp.ng);  // along the outward normal of the surface hit
    if (!contact) return std::nullopt;
    const MaterialFeatures& mf = m_view.analysis().materials[scene.geom_material(contact->hit.geom)];
    const SurfacePoint so = m_view.surface(contact->probe, contact->hit);
    return OtherMedium{mf.varying ? m_view.coefficients(so) : mf.constant, so.p, so.offset_scale};
}

std::optional<Hit> WhittedIntegrator::opaque_cover(const Hit& hit, const SurfacePoint& sp, RayCounters& counters) const {
    Hit cover = m_covers->at(sp.p, sp.offset_scale, sp.ng, counters);
    if (!cover.valid()) return std::nullopt;
    cover.t = hit.t;  // the same ray's hit at the same distance (cone width, absorption)
    return cover;
}

// The kernel. Every `if constexpr` below removes work a scene cannot need; the operations that
// remain run in the same order in every instantiation, so all kernels give bit-identical results
// on the scenes they are selected for (-ffp-contract=off keeps the compiler from fusing them).
template <KernelFeatures K>
Color WhittedIntegrator::shade(const Ray& ray, const Hit& hit, int depth, RayCounters& counters,
                               PrimaryInfo* primary, const RayCone& cone, float weight) const {
    const Scene& scene = m_view.scene();
    // Per material, only what it needs: a constant material (no textures, no vertex colors) needs
    // no UVs, colors or footprint, and its coefficients come from the analysis' table (the same
    // mapping, evaluated once at load).
    const MaterialFeatures& mf = m_view.analysis().materials[scene.geom_material(hit.geom)];
    // Both built in place: no default-constructed SurfacePoint to overwrite, and a constant
    // material's coefficients are read from the table, not copied (~100 bytes per hit each).
    const SurfacePoint sp = [&] {
        if constexpr (!K.attributes) return m_view.surface<false>(ray, hit, cone);
        else if constexpr (!K.tables) return m_view.surface<true>(ray, hit, cone);
        else return mf.varying ? m_view.surface<true>(ray, hit, cone) : m_view.surface<false>(ray, hit, cone);
    }();
    if constexpr (K.transmission) {
        // An opaque surface coinciding with a thin transmissive one is what the ray sees, whichever
        // of the two the accelerator reported (OpaqueCovers): shaded instead, as this ray's hit.
        if (m_covers && m_covers->candidate(object_index(scene, hit.geom, hit.inst))) [[unlikely]] {
            if (const std::optional<Hit> cover = opaque_cover(hit, sp, counters))
                return shade<K>(ray, *cover, depth, counters, primary, cone, weight);
        }
    }
    WhittedCoeffs varying;
    const WhittedCoeffs& c = [&]() -> const WhittedCoeffs& {
        if constexpr (!K.tables) return varying = m_view.coefficients(sp);
        else if constexpr (!K.attributes) return mf.constant;
        else return mf.varying ? (varying = m_view.coefficients(sp)) : mf.constant;
    }();
    const Material& mat = scene.materials[sp.material];
    // Secondary rays start where this cone arrived and keep its spread. Surface curvature would
    // widen (convex mirrors) or narrow it; it is ignored (flat-surface propagation).
    const RayCone secondary{cone.width_at(hit.t), cone.spread};

    // Orient the frame toward the viewer; `front` also says whether a ray enters the medium or
    // leaves it (shading_frame.h).
    // Named copies, not a structured binding: lambdas below capture them (clang 14 cannot
    // capture structured bindings).
    const ShadingFrame frame = shading_frame(sp, ray.dir);
    const Vec3f V = frame.V, Ng = frame.Ng, N = frame.N;
    const bool front = frame.front;

    // Touching dielectrics (DielectricContacts): the medium on the far side of this surface may
    // begin right here. `other` is that medium, entered when this one is left and left when this
    // one is entered.
    std::optional<OtherMedium> other;
    if constexpr (K.transmission) {
        if (m_contacts && !c.thin && !is_black(c.kt)) [[unlikely]]
            other = other_medium(hit, sp, counters);
    }

    if (primary) {
        primary->hit = true;
        primary->depth = hit.t;
        primary->normal = N;
        primary->albedo = c.kd + c.kr + c.kt;
        primary->prim = hit.prim;
        primary->inst = hit.inst;
    }

    // KHR_materials_unlit: the color is the answer.
    Color result = c.emission;
    const bool unlit = mat.model == MaterialModel::GltfPbr && mat.unlit;
    if (!unlit) {
        // Local model: I = Ia Ka + sum_i Is_i fat_i s_i (kd (N.L) + ks (N.H)^n).
        result += m_settings.ambient * c.ka;
        // The shadow-ray origin, computed at the first light that passes the tests below (a point
        // that no light reaches or faces casts no shadow ray and needs none).
        Vec3f shadow_org;
        bool have_shadow_org = false;
        const bool diffuse_or_specular = !is_black(c.kd) || !is_black(c.ks);
        auto add_light = [&](const Light& light) {
            LightSample ls = sample_light(light, sp.p);
            if (is_black(ls.intensity)) {  // beyond the range window or outside the spot cone
                ++counters.shadow_skipped_unreached;
                return;
            }
            const float n_dot_l = dot(N, ls.L);
            // The seed's `lum`: light only when N.L > 0 (shading normal). A light below the flat
            // facet but above the smooth surface still counts; the shadow ray decides.
            if (n_dot_l <= 0.f) {
                ++counters.shadow_skipped_facing;
                return;
            }
            // The light's term at the point, before its shadow factor.
            Color local = c.kd * n_dot_l;
            if (!is_black(c.ks)) {
                const Vec3f H = normalize(ls.L + V);
                const float n_dot_h = std::max(0.f, dot(N, H));
                // x^n <= e^(-n (1 - x)) (as ln x <= x - 1): where n (1 - x) >= 17 the highlight is
                // below 4.2e-8 (< 2^-24) of ks Is, invisible in every output (half's smallest normal
                // is 6e-5), and its pow is not evaluated. With the usual n of 40-300 that is most
                // points away from the highlight (docs/performance.md: the specular cutoff).
                if (c.n * (1.f - n_dot_h) < 17.f) local += c.ks * std::pow(n_dot_h, c.n);
            }
            // Nothing for the shadow factor to scale (kd = 0 and the highlight below the cutoff: a
            // glass or chrome surface away from its highlight): the shadow ray is not cast.
            if (is_black(local)) {
                ++counters.shadow_skipped_zero;
                return;
            }
            if (!have_shadow_org) {
                shadow_org = m_offset.origin(front ? sp.p_shadow : sp.p, sp.offset_scale, Ng);
                have_shadow_org = true;
            }
            Ray shadow;
            shadow.org = shadow_org;
            if (light.type == LightType::Directional) {
                shadow.dir = ls.L;
                shadow.tfar = kInfinity;
            } else {
                Vec3f to_light = Vec3f(light.position) - shadow_org;
                float d = length(to_light);
                if (!(d > 0.f)) return;
                shadow.dir = to_light / d;
                shadow.tfar = d * (1.f - 1e-5f);
            }
            count(counters, RayKind::Shadow);
            const Color s = m_accel.transmittance(shadow);
            if (is_black(s)) return;
            // Opaque scenes: s is exactly 1 here (nothing passes partially), and x * 1 == x.
            if constexpr (K.transmission) result += ls.intensity * s * local;
            else result += ls.intensity * local;
        };
        if (diffuse_or_specular) {
            if constexpr (K.tables) {
                // Only the lights that can reach this object (SceneAnalysis light reach).
                const std::span<const uint32_t> reach = m_view.lights_reaching(hit);
                counters.shadow_skipped_unreached += scene.lights.size() - reach.size();
                for (const uint32_t l : reach) add_light(scene.lights[l]);
            } else {
                for (const Light& light : scene.lights) add_light(light);
            }
        }

        // Recursive rays: Ks R + Kt T.
        if constexpr (K.mirror || K.transmission) {
            if (depth < m_settings.max_depth) {
                // With --fresnel (Schlick) the mirror weight follows F(theta) and transmission takes
                // what is left.
                auto [kr, kt] = secondary_weights(c.ks, c.kr, c.kt, std::clamp(dot(N, V), 0.f, 1.f), m_settings.fresnel);
                // Hall & Greenberg (1983): a branch whose accumulated weight falls below min_weight
                // cannot change the pixel visibly; it is not traced.
                if constexpr (K.transmission) {
                    // Through a shared face, the light crosses both surfaces.
                    const Color kt_through = other ? kt * other->c.kt : kt;
                    const float wt = weight * max_component(kt_through);
                    if (!is_black(kt) && wt < m_settings.min_weight) ++counters.secondary_skipped_cutoff;
                    if (!is_black(kt) && wt >= m_settings.min_weight) {
                        Ray t;
                        t.org = m_offset.origin(sp.p, sp.offset_scale, -Ng);
                        bool transmitted = true;
                        if (c.thin) {
                            t.dir = ray.dir;  // thin-walled: straight through
                        } else {
                            float eta = front ? 1.f / c.ior : c.ior;
                            if (other) {
                                // One interface between the two media: n_from / n_to in one step
                                // (no total internal reflection in a gap of zero width), and the ray
                                // starts past both surfaces.
                                eta *= front ? other->c.ior : 1.f / other->c.ior;
                                const Vec3f past_other = m_offset.origin(other->p, std::max(sp.offset_scale, other->offset_scale), -Ng);
                                if (dot(past_other - t.org, Ng) < 0.f) t.org = past_other;
                            }
                            auto dir = refract(ray.dir, N, eta);
                            if (dir && dot(*dir, Ng) < 0.f) t.dir = *dir;
                            else transmitted = false;  // total internal reflection
                        }
                        if (transmitted) {
                            result += kt_through * trace_kernel<K>(t, RayKind::Refraction, depth + 1, counters, nullptr,
                                                                   secondary, wt);
                        } else {
                            kr += kt;  // the transmitted energy goes to reflection
                        }
                    }
                }
                const float wr = weight * max_component(kr);
                if (!is_black(kr) && wr < m_settings.min_weight) ++counters.secondary_skipped_cutoff;
                if (!is_black(kr) && wr >= m_settings.min_weight) {
                    Vec3f R = reflect(V, N);
                    if (dot(R, Ng) <= 0.f) R = reflect(V, Ng);
                    Ray r;
                    r.org = m_offset.origin(sp.p, sp.offset_scale, Ng);
                    r.dir = normalize(R);
                    result += kr * trace_kernel<K>(r, RayKind::Reflection, depth + 1, counters, nullptr, secondary, wr);
                }
            }
        }
    }

    if constexpr (K.transmission) {
        // Beer-Lambert: leaving a volume, the light travelled `t` inside it.
        if (!front && !c.thin && !is_black(c.absorption)) result *= exp_neg(c.absorption * hit.t);
        // Entering this medium from a touching one: the light travelled `t` inside that one.
        if (front && other && !is_black(other->c.absorption)) result *= exp_neg(other->c.absorption * hit.t);

        // alpha BLEND: partial coverage mixed with what lies straight behind.
        if (mat.model == MaterialModel::GltfPbr && mat.alpha_mode == AlphaMode::Blend) {
            float alpha;
            if constexpr (K.tables) alpha = mf.varying ? std::clamp(m_view.material_inputs(mat, sp).base_color.w, 0.f, 1.f)
                                                       : mf.constant_alpha;
            else alpha = std::clamp(m_view.material_inputs(mat, sp).base_color.w, 0.f, 1.f);
            if (alpha < 1.f) {
                Ray behind;
                behind.org = m_offset.origin(sp.p, sp.offset_scale, -Ng);
                behind.dir = ray.dir;
                // Below min_weight the branch behind is dropped (contributes 0) like the others.
                const float wb = weight * (1.f - alpha);
                Color b = m_settings.background;
                if (depth < m_settings.max_depth) {
                    if (wb >= m_settings.min_weight)
                        b = trace_kernel<K>(behind, RayKind::Refraction, depth + 1, counters, nullptr, secondary, wb);
                    else {
                        b = Color(0.f);
                        ++counters.secondary_skipped_cutoff;
                    }
                }
                result = result * alpha + b * (1.f - alpha);
            }
        }
    }
    return result;
}

}  // namespace whitted
