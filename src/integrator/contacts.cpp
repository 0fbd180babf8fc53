#include "integrator/contacts.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "accel/factory/create_accelerator.h"

namespace whitted {

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
/// (conservative) for meshes and quadrics.
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
    for (size_t i = 0; i < scene.quadrics.size(); ++i) {
        const Quadric& q = scene.quadrics[i];
        if (!select(q.material)) continue;
        objects.push_back({object_index(scene, scene.quadric_geom_id(i), kInvalidId), GeomKind::Quadric, quadric_bounds(q)});
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
    // Analytic objects (spheres, quadrics, planes: geometry ids after the meshes), with the one
    // material.
    auto extract = [&](const auto& from, auto& to, uint32_t first_geom) {
        for (size_t i = 0; i < from.size(); ++i) {
            const uint32_t g = first_geom + uint32_t(i);
            if (!keep[object_index(scene, g, kInvalidId)]) continue;
            to.push_back(from[i]);
            to.back().material = 0;
            geom.push_back(g);
        }
    };
    extract(scene.spheres, sub.spheres, scene.sphere_geom_id(0));
    extract(scene.quadrics, sub.quadrics, scene.quadric_geom_id(0));
    extract(scene.planes, sub.planes, scene.plane_geom_id(0));
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


std::shared_ptr<const OpaqueCovers> OpaqueCovers::find(const SceneView& view) {
    const Scene& scene = view.scene();
    const SceneAnalysis& analysis = view.analysis();
    // Thin sheets and solid dielectrics alike: a glass slab lying on a table has its bottom face in
    // the table's plane, and the refracted ray must see the table, not exit into it.
    const std::vector<ContactObject> covered = contact_objects(scene, [&](uint32_t material) {
        return analysis.materials[material].transmission;
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

Hit ContactSearch::probe_at(const Vec3f& p, const Vec3f& n, float reach, Ray& probe) const {
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

bool DielectricContacts::accept(const Ray& ray, const Hit& hit, RayKind) const {
    // Front faces by the same winding rule as SceneView (ng from the world vertices in double;
    // spheres and quadrics: outward; planes: `normal`).
    const Vec3d d(ray.dir);
    switch (m_sub.geom_kind(hit.geom)) {
        case GeomKind::Mesh: {
            Vec3d p[3];
            m_sub.world_triangle(hit.inst, hit.prim, p);
            return dot(cross(p[1] - p[0], p[2] - p[0]), d) < 0.0;
        }
        case GeomKind::Sphere: {
            const Sphere& s = m_sub.sphere_of(hit.geom);
            return dot(Vec3d(ray.org) + d * double(hit.t) - s.center, d) < 0.0;
        }
        case GeomKind::Quadric:
            return dot(quadric_point(m_sub.quadric_of(hit.geom), Vec3d(ray.org) + d * double(hit.t), int(hit.prim)).n, d) < 0.0;
        case GeomKind::Plane: return dot(m_sub.plane_of(hit.geom).normal, d) < 0.0;
    }
    return false;
}

}  // namespace whitted
