// Shared pieces of the accelerator tests: procedural meshes, filters with known answers, ray
// sets (random and edge cases) and the hit comparison with its tie rule.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "accel/accelerator.h"
#include "accel/common/geometry.h"
#include "scene/scene.h"

namespace whitted::test {

/// Every mesh opaque, no filter calls.
class OpaqueFilter final : public SurfaceFilter {
public:
    bool accept(const Ray&, const Hit&, RayKind) const override { return true; }
    Color transmittance(const Ray&, const Hit&) const override { return Color(0.f); }
    uint32_t mesh_flags(uint32_t) const override { return 0; }
};

/// Filter with closed-form answers: meshes with an odd index need accept(), which rejects every
/// third triangle (a cut-out); meshes with index % 3 == 2 are transparent with Kt depending on
/// the mesh (per channel) so that products reveal double counting.
class PatternFilter final : public SurfaceFilter {
public:
    bool accept(const Ray&, const Hit& h, RayKind) const override { return h.prim % 3 != 0; }
    Color transmittance(const Ray&, const Hit& h) const override {
        if (h.geom % 3 != 2) return h.geom % 2 == 1 && h.prim % 3 == 0 ? Color(1.f) : Color(0.f);
        return Color(0.9f, 0.8f - 0.01f * float(h.geom % 7), 0.5f);
    }
    uint32_t mesh_flags(uint32_t g) const override {
        uint32_t f = 0;
        if (g % 2 == 1) f |= kNeedsAccept | kNeedsTransmittance;
        if (g % 3 == 2) f |= kNeedsTransmittance;
        return f;
    }
};

/// Filter over every kind of geometry (ids as in Scene: meshes, spheres, planes), with answers
/// a test can predict. Meshes follow PatternFilter. Spheres by index % 4: 0 opaque;
/// 1 transparent (Kt depends on the sphere); 2 cut away entirely (accept() false, transmittance
/// 1); 3 the entering side cut away (accept() only where the ray leaves the sphere; transmittance
/// 1 on entering, Kt 0.6 on leaving). Planes by index % 3: 0 opaque; 1 transparent; 2 a checker
/// cut-out of 0.7-unit squares in the plane's (u_axis, normal x u_axis) frame. Quadrics by
/// index % 3: 0 opaque; 1 transparent (Kt 0.7); 2 cut away where the ray leaves through the outward
/// normal (accept() false there, transmittance 1; Kt 0.5 where it enters).
class MixedFilter final : public SurfaceFilter {
public:
    explicit MixedFilter(const Scene& s)
        : m_meshes(uint32_t(s.meshes.size())), m_spheres(s.spheres), m_quadrics(s.quadrics), m_planes(s.planes) {}

    bool accept(const Ray& r, const Hit& h, RayKind k) const override {
        if (h.geom < m_meshes) return m_pattern.accept(r, h, k);
        if (const Sphere* sp = sphere(h.geom)) return sphere_index(h.geom) % 4 == 3 ? leaving(r, h, *sp) : false;
        if (const Quadric* q = quadric(h.geom)) return quadric_index(h.geom) % 3 != 2 || !leaving(r, h, *q);
        return plane_checker(r, h);
    }
    Color transmittance(const Ray& r, const Hit& h) const override {
        if (h.geom < m_meshes) return m_pattern.transmittance(r, h);
        if (const Quadric* q = quadric(h.geom)) {
            switch (quadric_index(h.geom) % 3) {
                case 1: return Color(0.7f);
                case 2: return leaving(r, h, *q) ? Color(1.f) : Color(0.5f);
                default: return Color(0.f);
            }
        }
        if (const Sphere* sp = sphere(h.geom)) {
            switch (sphere_index(h.geom) % 4) {
                case 1: return Color(0.9f, 0.7f - 0.02f * float(sphere_index(h.geom) % 9), 0.8f);
                case 2: return Color(1.f);
                case 3: return leaving(r, h, *sp) ? Color(0.6f) : Color(1.f);
                default: return Color(0.f);
            }
        }
        const uint32_t i = plane_index(h.geom);
        if (i % 3 == 1) return Color(0.75f, 0.5f, 0.95f);
        return i % 3 == 2 && !plane_checker(r, h) ? Color(1.f) : Color(0.f);
    }
    uint32_t mesh_flags(uint32_t g) const override {
        if (g < m_meshes) return m_pattern.mesh_flags(g);
        if (sphere(g)) {
            const uint32_t i = sphere_index(g) % 4;
            return i == 0 ? 0u : i == 1 ? kNeedsTransmittance : kNeedsAccept | kNeedsTransmittance;
        }
        if (quadric(g)) {
            const uint32_t i = quadric_index(g) % 3;
            return i == 0 ? 0u : i == 1 ? kNeedsTransmittance : kNeedsAccept | kNeedsTransmittance;
        }
        const uint32_t i = plane_index(g) % 3;
        return i == 0 ? 0u : i == 1 ? kNeedsTransmittance : kNeedsAccept | kNeedsTransmittance;
    }

private:
    uint32_t sphere_index(uint32_t g) const { return g - m_meshes; }
    uint32_t quadric_index(uint32_t g) const { return g - m_meshes - uint32_t(m_spheres.size()); }
    uint32_t plane_index(uint32_t g) const { return quadric_index(g) - uint32_t(m_quadrics.size()); }
    const Sphere* sphere(uint32_t g) const { return g - m_meshes < m_spheres.size() ? &m_spheres[g - m_meshes] : nullptr; }
    const Quadric* quadric(uint32_t g) const {
        return g - m_meshes >= m_spheres.size() && quadric_index(g) < m_quadrics.size() ? &m_quadrics[quadric_index(g)] : nullptr;
    }
    static bool leaving(const Ray& r, const Hit& h, const Quadric& q) {
        return dot(quadric_point(q, Vec3d(r.org) + Vec3d(r.dir) * double(h.t), int(h.prim)).n, Vec3d(r.dir)) > 0.0;
    }
    static bool leaving(const Ray& r, const Hit& h, const Sphere& s) {
        const Vec3d p = Vec3d(r.org) + Vec3d(r.dir) * double(h.t);
        return dot(p - s.center, Vec3d(r.dir)) > 0.0;
    }
    bool plane_checker(const Ray& r, const Hit& h) const {
        const Plane& pl = m_planes[plane_index(h.geom)];
        const Vec3d p = Vec3d(r.org) + Vec3d(r.dir) * double(h.t) - pl.point;
        const double u = dot(p, pl.u_axis) / 0.7, v = dot(p, cross(pl.normal, pl.u_axis)) / 0.7;
        return (int64_t(std::floor(u)) + int64_t(std::floor(v))) % 2 == 0;
    }

    PatternFilter m_pattern;
    uint32_t m_meshes;
    std::vector<Sphere> m_spheres;
    std::vector<Quadric> m_quadrics;
    std::vector<Plane> m_planes;
};

inline Mesh make_uv_sphere(Vec3f c, float r, int rings, int segments) {
    Mesh m;
    m.name = "sphere";
    for (int i = 0; i <= rings; ++i)
        for (int j = 0; j <= segments; ++j) {
            const float th = kPi * float(i) / float(rings), ph = 2.f * kPi * float(j) / float(segments);
            m.positions.push_back(c + Vec3f(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)) * r);
        }
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const uint32_t a = uint32_t(i * (segments + 1) + j), b = a + uint32_t(segments + 1);
            for (uint32_t k : {a, b, a + 1, a + 1, b, b + 1}) m.indices.push_back(k);
        }
    m.normals.assign(m.positions.size(), Vec3f(0, 1, 0));
    return m;
}

inline Mesh make_soup(uint32_t n, uint32_t seed, float extent, float size) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(-extent, extent), off(-size, size);
    Mesh m;
    m.name = "soup";
    for (uint32_t i = 0; i < n; ++i) {
        const Vec3f c{pos(rng), pos(rng), pos(rng)};
        for (int k = 0; k < 3; ++k) {
            m.positions.push_back(c + Vec3f(off(rng), off(rng), off(rng)));
            m.indices.push_back(uint32_t(m.positions.size() - 1));
        }
    }
    m.normals.assign(m.positions.size(), Vec3f(0, 1, 0));
    return m;
}

/// Height field on [-1, 1]^2 (grid of quads split in two), z up.
inline Mesh make_terrain(int n, float amplitude) {
    Mesh m;
    m.name = "terrain";
    for (int y = 0; y <= n; ++y)
        for (int x = 0; x <= n; ++x) {
            const float u = -1.f + 2.f * float(x) / float(n), v = -1.f + 2.f * float(y) / float(n);
            m.positions.push_back({u, v, amplitude * std::sin(4.f * u) * std::cos(3.f * v)});
        }
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const uint32_t a = uint32_t(y * (n + 1) + x), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
            for (uint32_t k : {a, b, d, a, d, c}) m.indices.push_back(k);
        }
    m.normals.assign(m.positions.size(), Vec3f(0, 0, 1));
    return m;
}

inline void add_instance(Scene& s, uint32_t mesh, const Mat4d& xf = Mat4d::identity()) {
    Instance inst;
    inst.mesh = mesh;
    inst.world_from_object = xf;
    s.instances.push_back(inst);
}

inline uint32_t add_mesh_instance(Scene& s, Mesh m, const Mat4d& xf = Mat4d::identity()) {
    s.meshes.push_back(std::move(m));
    add_instance(s, uint32_t(s.meshes.size() - 1), xf);
    return uint32_t(s.meshes.size() - 1);
}

/// Random rays from around the scene box towards points inside it, plus the edge cases: through
/// vertices, through edge midpoints, parallel to the axes (with +0 and -0 components), origins on
/// surfaces (tnear = 0). Rays with `tfar` set exactly to a hit are added by the tests.
inline std::vector<Ray> make_rays(const Scene& s, uint32_t count, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    const Bounds3d b = s.world_bounds();
    const Vec3d c = b.center(), d = b.diagonal();
    auto inside = [&] { return Vec3d{b.lo.x + u01(rng) * d.x, b.lo.y + u01(rng) * d.y, b.lo.z + u01(rng) * d.z}; };
    auto outside = [&] {
        const double th = std::acos(2 * u01(rng) - 1), ph = 2 * 3.14159265358979 * u01(rng);
        return c + Vec3d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)) * (length(d) * 1.5);
    };
    std::vector<Ray> rays;
    auto add = [&](Vec3d o, Vec3d target) {
        Ray r;
        r.org = Vec3f(o);
        r.dir = Vec3f(target - o);
        rays.push_back(r);
    };
    for (uint32_t i = 0; i < count; ++i) add(u01(rng) < 0.7 ? outside() : inside(), inside());
    // Through vertices and edge midpoints of random triangles.
    std::uniform_int_distribution<size_t> pick_inst(0, s.instances.size() - 1);
    for (uint32_t i = 0; i < count / 4 && !s.instances.empty(); ++i) {
        const uint32_t inst = uint32_t(pick_inst(rng));
        const Mesh& m = s.meshes[s.instances[inst].mesh];
        if (m.triangle_count() == 0) continue;
        const uint32_t prim = uint32_t(rng() % m.triangle_count());
        Vec3d p[3];
        s.world_triangle(inst, prim, p);
        add(outside(), p[i % 3]);
        add(outside(), (p[i % 3] + p[(i + 1) % 3]) * 0.5);
        // Origin on the surface, leaving it.
        Ray r;
        r.org = Vec3f((p[0] + p[1] + p[2]) * (1.0 / 3.0));
        r.dir = Vec3f(outside() - Vec3d(r.org));
        rays.push_back(r);
    }
    // Axis-parallel rays through the box, both signs of zero in the other components.
    for (uint32_t i = 0; i < count / 8; ++i) {
        const int axis = int(i % 3);
        Vec3d o = inside();
        o[axis] = b.lo[axis] - 0.5 * d[axis] - 1.0;
        Ray r;
        r.org = Vec3f(o);
        r.dir = Vec3f(0.f);
        r.dir[axis] = 1.f;
        if (i & 8) r.dir[(axis + 1) % 3] = -0.f;
        rays.push_back(r);
    }
    return rays;
}

/// Edge cases of analytic geometry: for each sphere, rays from its centre, from points on its
/// surface (inwards and outwards), tangent to it and aimed at its centre from outside; for each
/// plane, rays lying in it, parallel to it (with +0 and -0 components along the normal when the
/// normal is an axis) and starting on it.
inline std::vector<Ray> make_analytic_rays(const Scene& s, uint32_t per_primitive, uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> gauss;
    auto unit = [&] { return normalize(Vec3d(gauss(rng), gauss(rng), gauss(rng))); };
    std::vector<Ray> rays;
    auto add = [&](Vec3d o, Vec3d d) {
        Ray r;
        r.org = Vec3f(o);
        r.dir = Vec3f(d);
        rays.push_back(r);
    };
    for (const Sphere& sp : s.spheres)
        for (uint32_t i = 0; i < per_primitive; ++i) {
            const Vec3d n = unit(), d = unit(), side = normalize(cross(n, unit()));
            add(sp.center, d);                                              // from the centre
            add(sp.center + n * sp.radius, dot(d, n) < 0 ? d : -d);           // on the surface, inwards
            add(sp.center + n * sp.radius, dot(d, n) > 0 ? d : -d);           // on the surface, outwards
            add(sp.center + side * sp.radius - n * (3 * sp.radius), n);       // tangent
            add(sp.center + n * (4 * sp.radius + 1), -n);                     // at the centre
        }
    for (const Quadric& q : s.quadrics)
        for (uint32_t i = 0; i < per_primitive; ++i) {
            // Object-space points on the rims, the side and the caps, and the axis, into the world.
            const Mat4d& m = q.world_from_object;
            const double phi = 2.0 * kPiD * std::uniform_real_distribution<double>(0, 1)(rng);
            const Vec3d radial{std::cos(phi), std::sin(phi), 0.0};
            const Vec3d rim0 = m.apply_point(radial * q.radius0);
            const Vec3d rim1 = m.apply_point(radial * q.radius1 + Vec3d{0, 0, q.kind == QuadricKind::Disc ? 0.0 : q.height});
            const Vec3d mid = m.apply_point(radial * (0.5 * (q.radius0 + q.radius1)) + Vec3d{0, 0, 0.5 * q.height});
            const Vec3d axis0 = m.apply_point({0, 0, 0}), axis1 = m.apply_point({0, 0, q.height});
            const double size = length(quadric_bounds(q).diagonal());
            const Vec3d d = unit();
            add(rim0 - d * (2 * size), d);                                  // through a rim
            add(rim1 - d * (2 * size), d);
            add(mid - d * (2 * size), d);                                   // through the side
            add(axis0 + (axis0 - axis1) * 2.0, axis1 - axis0);              // along the axis
            const Vec3d tangent = normalize(cross(m.apply_vector(radial), m.apply_vector({0, 0, 1})));
            add(m.apply_point(radial * (q.radius0 * 1.0000001)) - tangent * size, tangent);  // grazing the base rim
            add(axis0 * 0.5 + axis1 * 0.5, d);                              // from inside
        }
    for (const Plane& pl : s.planes)
        for (uint32_t i = 0; i < per_primitive; ++i) {
            const Vec3d v = cross(pl.normal, pl.u_axis);
            const Vec3d in_plane = pl.u_axis * gauss(rng) + v * gauss(rng);
            const Vec3d on = pl.point + pl.u_axis * (3 * gauss(rng)) + v * (3 * gauss(rng));
            add(on, in_plane);                                                // lying in the plane
            Ray r;
            r.org = Vec3f(on + pl.normal * (0.5 * gauss(rng)));
            r.dir = Vec3f(in_plane);
            for (int k = 0; k < 3; ++k)
                if (std::fabs(pl.normal[k]) == 1.0) r.dir[k] = (i & 1) ? -0.f : 0.f;  // exactly parallel, +-0
            rays.push_back(r);
            add(on, unit());                                                  // starting on it
        }
    return rays;
}

/// Outcome of comparing a backend's closest hit with the oracle's on one ray.
enum class Agreement { Same, Tie, Differ };

/// Same primitive (and t within `rel_tol`), or a tie: a different primitive at the same t within
/// `rel_tol` (shared edges and vertices, coplanar overlaps), which either backend may report.
inline Agreement compare_hits(const Hit& a, const Hit& b, float rel_tol) {
    if (!a.valid() || !b.valid()) return a.valid() == b.valid() ? Agreement::Same : Agreement::Differ;
    const bool close = std::fabs(a.t - b.t) <= rel_tol * std::max(std::fabs(a.t), std::fabs(b.t));
    if (a.prim == b.prim && a.geom == b.geom && a.inst == b.inst) return close ? Agreement::Same : Agreement::Differ;
    return close ? Agreement::Tie : Agreement::Differ;
}

}  // namespace whitted::test
