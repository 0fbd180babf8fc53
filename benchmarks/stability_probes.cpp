// Numerical stability probes (see stability_probes.h and docs/numerical-stability.md).
#include "benchmarks/stability_probes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <utility>
#include <cstdio>
#include <cstdlib>

#include "accel/common/quadric.h"
#include "accel/common/sphere.h"
#include "accel/factory/create_accelerator.h"
#include "core/fp_mode.h"
#include "core/ray_offset.h"
#include "integrator/contacts.h"
#include "integrator/camera.h"
#include "integrator/scene_view.h"
#include "integrator/shading_frame.h"
#include "shading/light_sample.h"
#include "shading/optics.h"

namespace whitted::stress {

namespace {

const Vec3d kTranslationDir{0.8, 0.36, -0.48};  // unit length, no component exactly representable

Vec3d random_unit(std::mt19937_64& rng) {
    std::normal_distribution<double> g;
    for (;;) {
        const Vec3d v{g(rng), g(rng), g(rng)};
        const double l = length(v);
        if (l > 1e-6) return v / l;
    }
}

/// Orthonormal frame around unit n.
void frame(const Vec3d& n, Vec3d& t, Vec3d& b) {
    const Vec3d a = std::fabs(n.x) < 0.7 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
    t = normalize(cross(a, n));
    b = cross(n, t);
}

/// Direction with the given cosine to unit n, random azimuth.
Vec3d direction_at_cosine(const Vec3d& n, double cos_theta, std::mt19937_64& rng) {
    Vec3d t, b;
    frame(n, t, b);
    const double phi = std::uniform_real_distribution<double>(0.0, 2.0 * kPiD)(rng);
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    return n * cos_theta + (t * std::cos(phi) + b * std::sin(phi)) * sin_theta;
}

/// Half of the directions uniform in the hemisphere, half grazing (cos in [1e-4, 1e-1], log-uniform).
Vec3d hemisphere_direction(const Vec3d& n, int j, std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    const double c = j % 2 == 0 ? std::max(1e-6, u01(rng)) : std::pow(10.0, -4.0 + 3.0 * u01(rng));
    return direction_at_cosine(n, c, rng);
}

/// Angle between two unit vectors, accurate near 0 (atan2 of |cross| and dot, not acos).
double angle_between(const Vec3d& a, const Vec3d& b) { return std::atan2(length(cross(a, b)), dot(a, b)); }

uint32_t add_material(Scene& s) {
    Material m;
    m.name = "probe";
    m.model = MaterialModel::Classic;
    m.classic.kd = Color(0.5f);
    s.materials.push_back(m);
    return uint32_t(s.materials.size() - 1);
}

void add_instance(Scene& s, uint32_t mesh, const Mat4d& xf) {
    Instance inst;
    inst.mesh = mesh;
    inst.world_from_object = xf;
    s.instances.push_back(inst);
}

/// Filter of the self-intersection probe: geometry "A" is opaque, the neighbours transmit 0.5;
/// camera rays accept only A (they pass through the outer neighbour to reach it).
class ProbeFilter final : public SurfaceFilter {
public:
    explicit ProbeFilter(const Scene& s) : m_scene(s) {}
    bool is_a(const Hit& h) const {
        return m_scene.geom_kind(h.geom) == GeomKind::Mesh ? h.inst == 0 : h.geom == m_scene.sphere_geom_id(0);
    }
    bool accept(const Ray&, const Hit& h, RayKind kind) const override { return kind != RayKind::Camera || is_a(h); }
    Color transmittance(const Ray&, const Hit& h) const override { return is_a(h) ? Color(0.f) : Color(0.5f); }
    uint32_t mesh_flags(uint32_t) const override { return kNeedsAccept | kNeedsTransmittance; }

private:
    const Scene& m_scene;
};

class OpaqueFilter final : public SurfaceFilter {
public:
    bool accept(const Ray&, const Hit&, RayKind) const override { return true; }
    Color transmittance(const Ray&, const Hit&) const override { return Color(0.f); }
    uint32_t mesh_flags(uint32_t) const override { return 0; }
};

}  // namespace

// ---------------------------------------------------------------------------------------------

float ulp(float x) {
    x = std::fabs(x);
    if (!std::isfinite(x)) return x;
    return std::nextafter(x, kInfinity) - x;
}

Vec3f wachter_binder_2019(const Vec3f& p, float, const Vec3f& n) {
    Vec3f o;
    for (int k = 0; k < 3; ++k) {
        const int32_t of = int32_t(256.f * n[k]);
        const float pi = std::bit_cast<float>(std::bit_cast<int32_t>(p[k]) + (p[k] < 0.f ? -of : of));
        o[k] = std::fabs(p[k]) < 1.f / 32.f ? p[k] + n[k] / 65536.f : pi;
    }
    return o;
}

Mat4d placement(double scale, double translation, bool rotate) {
    Mat4d r;
    if (rotate) {
        // A fixed rotation without axis-aligned structure (unit quaternion).
        const double q[4] = {0.3, -0.5, 0.2, 0.79};
        const double l = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        r = Mat4d::rotate(q[0] / l, q[1] / l, q[2] / l, q[3] / l);
    }
    return Mat4d::translate(kTranslationDir * translation) * r * Mat4d::scale(Vec3d(scale));
}

Distribution distribution(std::vector<double>& v) {
    Distribution d;
    d.count = v.size();
    if (v.empty()) return d;
    std::sort(v.begin(), v.end());
    d.median = v[v.size() / 2];
    d.p999 = v[std::min(v.size() - 1, size_t(std::ceil(0.999 * double(v.size()))) - 1)];
    d.max = v.back();
    return d;
}

Mesh make_closed_sphere(int rings, int segments, bool smooth_normals) {
    Mesh m;
    m.name = "closed sphere";
    m.positions.push_back({0, 1, 0});
    for (int i = 1; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const double th = kPiD * i / rings, ph = 2.0 * kPiD * j / segments;
            m.positions.push_back(Vec3f(Vec3d(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph))));
        }
    m.positions.push_back({0, -1, 0});
    const uint32_t south = uint32_t(m.positions.size() - 1);
    auto ring = [&](int i, int j) { return uint32_t(1 + (i - 1) * segments + (j % segments)); };
    auto tri = [&](uint32_t a, uint32_t b, uint32_t c) {
        // Wind counter-clockwise seen from outside (the sphere is convex around the origin).
        const Vec3f pa = m.positions[a], pb = m.positions[b], pc = m.positions[c];
        if (dot(cross(pb - pa, pc - pa), pa + pb + pc) < 0.f) std::swap(b, c);
        m.indices.insert(m.indices.end(), {a, b, c});
    };
    for (int j = 0; j < segments; ++j) tri(0, ring(1, j), ring(1, j + 1));
    for (int i = 1; i + 1 < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            tri(ring(i, j), ring(i + 1, j), ring(i + 1, j + 1));
            tri(ring(i, j), ring(i + 1, j + 1), ring(i, j + 1));
        }
    for (int j = 0; j < segments; ++j) tri(south, ring(rings - 1, j + 1), ring(rings - 1, j));
    if (smooth_normals)
        for (const Vec3f& p : m.positions) m.normals.push_back(normalize(p));
    return m;
}

Mesh make_closed_cube(int n) {
    Mesh m;
    m.name = "closed cube";
    std::map<std::tuple<int, int, int>, uint32_t> ids;
    auto vertex = [&](int i, int j, int k) {
        auto [it, inserted] = ids.emplace(std::make_tuple(i, j, k), uint32_t(m.positions.size()));
        if (inserted) m.positions.push_back(Vec3f(Vec3d(i, j, k) * (2.0 / n) - Vec3d(1.0)));
        return it->second;
    };
    auto tri = [&](uint32_t a, uint32_t b, uint32_t c) {
        const Vec3f pa = m.positions[a], pb = m.positions[b], pc = m.positions[c];
        if (dot(cross(pb - pa, pc - pa), pa + pb + pc) < 0.f) std::swap(b, c);
        m.indices.insert(m.indices.end(), {a, b, c});
    };
    // Six faces: axis a fixed at 0 or n, the other two on the grid.
    for (int axis = 0; axis < 3; ++axis)
        for (int side : {0, n})
            for (int u = 0; u < n; ++u)
                for (int v = 0; v < n; ++v) {
                    auto at = [&](int du, int dv) {
                        int c[3];
                        c[axis] = side;
                        c[(axis + 1) % 3] = u + du;
                        c[(axis + 2) % 3] = v + dv;
                        return vertex(c[0], c[1], c[2]);
                    };
                    tri(at(0, 0), at(1, 0), at(1, 1));
                    tri(at(0, 0), at(1, 1), at(0, 1));
                }
    return m;
}

bool is_closed_mesh(const Mesh& mesh) {
    std::map<std::tuple<float, float, float>, uint32_t> weld;
    std::vector<uint32_t> id(mesh.positions.size());
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
        const Vec3f& p = mesh.positions[i];
        id[i] = weld.emplace(std::make_tuple(p.x, p.y, p.z), uint32_t(weld.size())).first->second;
    }
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = id[mesh.indices[t + size_t(k)]], b = id[mesh.indices[t + size_t((k + 1) % 3)]];
            if (a == b) return false;
            ++directed[{a, b}];
        }
    for (const auto& [e, n] : directed) {
        auto it = directed.find({e.second, e.first});
        if (n != 1 || it == directed.end() || it->second != 1) return false;
    }
    return !directed.empty();
}

// ---------------------------------------------------------------------------------------------
// 1. Self-intersection

SelfIntersectionResult probe_self_intersection(const SelfIntersectionConfig& cfg) {
    const ScopedFlushDenormals ftz;  // as the renderer traces (render.cpp); the caller's mode after
    SelfIntersectionResult res;
    const double s = cfg.scale;
    const bool quad = cfg.surface == ProbeSurface::TiltedQuad;
    const bool analytic = cfg.surface == ProbeSurface::AnalyticSphere;
    const double translation = quad ? 0.0 : cfg.translation;
    const Vec3d centre = kTranslationDir * translation;
    // Gap: gap_ulps ulps of the largest coordinate any point or vertex of A can have (at least the
    // offset unit ulp(max(max|p|, offset_scale)) of every point, ray_offset.h), divided by the
    // smallest distance of a facet plane from the centre, so every neighbour facet lies at least
    // gap_ulps offset units away from its counterpart on A. The quad's corners reach beyond s.
    float bound = float(std::max({std::fabs(centre.x), std::fabs(centre.y), std::fabs(centre.z)}) + s);
    if (quad)
        for (const Vec3d corner : {Vec3d{-1, -1, 0}, Vec3d{1, -1, 0}, Vec3d{1, 1, 0}, Vec3d{-1, 1, 0}}) {
            const Vec3d w = placement(s, 0.0).apply_point(corner);
            bound = std::max(bound, float(std::max({std::fabs(w.x), std::fabs(w.y), std::fabs(w.z)})));
        }
    const double gap = cfg.gap_ulps * double(ulp(bound));
    const int rings = 24, segments = 48;
    const double h_min = analytic || quad ? 1.0 : std::cos(kPiD / rings) * std::cos(kPiD / segments);
    const double d = gap / (s * h_min);
    // In collapsed cases the gap can exceed the object's size (d >= 1): the inner neighbour C would
    // have a non-positive scale (a mirrored copy outside A, which outward shadow rays crossed as
    // well as B: the "double counts" of docs/numerical-stability.md, open item 6). There is no
    // room for C then; it is left out and inward rays judge self-hits only.
    const bool has_inner = quad || d < 1.0;
    res.inner_neighbour = has_inner;
    res.gap_world = gap;

    Scene scene;
    const uint32_t mat = add_material(scene);
    Vec3d quad_normal{0, 0, 1};
    if (analytic) {
        for (double f : {1.0, 1.0 + d, 1.0 - d}) {
            if (f <= 0.0) continue;  // no room for C: see has_inner above
            Sphere sp;
            sp.center = centre;
            sp.radius = s * f;
            sp.material = mat;
            scene.spheres.push_back(sp);
        }
    } else if (quad) {
        // A square of half-size s through the world origin, tilted; the neighbours are parallel
        // copies moved by the gap along its normal.
        Mesh m;
        m.name = "tilted quad";
        m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
        m.indices = {0, 1, 2, 0, 2, 3};
        m.material = mat;
        scene.meshes.push_back(std::move(m));
        const Mat4d a = placement(s, 0.0);
        quad_normal = normalize(a.inverse_affine().transposed().apply_vector({0, 0, 1}));
        for (double f : {0.0, gap, -gap}) add_instance(scene, 0, Mat4d::translate(quad_normal * f) * a);
    } else {
        Mesh mesh = make_closed_sphere(rings, segments, cfg.smooth_normals);
        mesh.material = mat;
        scene.meshes.push_back(std::move(mesh));
        for (double f : {1.0, 1.0 + d, 1.0 - d})
            if (f > 0.0) add_instance(scene, 0, placement(s * f, translation));  // see has_inner above
    }
    Camera cam;
    scene.cameras.push_back(cam);

    ProbeFilter filter(scene);
    const SceneView view(scene, MappingOptions{});
    const auto accel = create_accelerator(cfg.accel, scene, filter, AccelConfig{cfg.robust, 0});
    const OffsetFn offset = cfg.offset ? cfg.offset : OffsetFn([policy = accel->ray_offset()](const Vec3f& p, float scale, const Vec3f& n) {
        return policy.origin(p, scale, n);
    });

    // Signed distance of x from the exact surface of A (positive outside), in double.
    auto surface_distance = [&](const Vec3d& x, const Hit& hit) {
        if (analytic) return length(x - centre) - s;
        Vec3d w[3];
        scene.world_triangle(0, hit.prim, w);
        return dot(x - w[0], normalize(cross(w[1] - w[0], w[2] - w[0])));
    };
    // Exact outward normal of A at the hit.
    auto exact_normal = [&](const Vec3d& x, const Hit& hit) {
        if (analytic) return normalize(x - centre);
        Vec3d w[3];
        scene.world_triangle(0, hit.prim, w);
        return normalize(cross(w[1] - w[0], w[2] - w[0]));
    };
    // Which side of the neighbour `hit` a ray with direction `dir` crossed: +1 leaving, -1 entering.
    auto crossing_side = [&](const Ray& r, const Hit& h) {
        const Vec3d p = Vec3d(r.org) + Vec3d(r.dir) * double(h.t);
        Vec3d n;
        if (analytic) {
            n = p - centre;
        } else {
            Vec3d w[3];
            scene.world_triangle(h.inst, h.prim, w);
            n = cross(w[1] - w[0], w[2] - w[0]);
        }
        return dot(n, Vec3d(r.dir)) > 0.0 ? 1 : -1;
    };

    std::mt19937_64 rng(cfg.seed);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    const Mesh* mesh = analytic ? nullptr : &scene.meshes[0];
    res.min_offset_ulps = 1e300;
    for (size_t i = 0; i < cfg.points; ++i) {
        // A target point on A and its exact normal.
        Vec3d target, n_target;
        if (analytic) {
            n_target = random_unit(rng);
            target = centre + n_target * s;
        } else if (quad) {
            // Log-uniform distance from the origin: 1e-4 s .. s (inside the square).
            const double r = s * std::pow(10.0, -4.0 * u01(rng)), ph = 2.0 * kPiD * u01(rng);
            target = placement(s, 0.0).apply_point(Vec3d(std::cos(ph), std::sin(ph), 0.0) * (r / s * 0.99));
            n_target = quad_normal;
        } else {
            const uint32_t prim = uint32_t(u01(rng) * double(mesh->triangle_count())) % uint32_t(mesh->triangle_count());
            Vec3d w[3];
            scene.world_triangle(0, prim, w);
            double a = u01(rng), b = u01(rng);
            if (a + b > 1.0) a = 1.0 - a, b = 1.0 - b;
            target = w[0] * (1.0 - a - b) + w[1] * a + w[2] * b;
            n_target = normalize(cross(w[1] - w[0], w[2] - w[0]));
        }
        // Camera ray from outside B towards it.
        const Vec3d from = direction_at_cosine(n_target, 0.2 + 0.8 * u01(rng), rng);
        const double reach = quad ? std::max(length(target), 1e-3 * s) : 0.5 * s;
        Ray cam_ray;
        cam_ray.org = Vec3f(target + from * reach);
        cam_ray.dir = Vec3f(-from);
        const Hit hit = accel->intersect(cam_ray, RayKind::Camera);
        if (!hit.valid() || !filter.is_a(hit)) {
            ++res.camera_misses;
            continue;
        }
        ++res.points;
        // Exactly what the integrator does at a hit (whitted_integrator.cpp, shade()).
        SurfacePoint sp = view.surface(cam_ray, hit);
        if (cfg.exact_point && !analytic) {
            // The proposed SceneView: world vertices and the barycentric blend in double, one rounding.
            Vec3d w[3];
            scene.world_triangle(0, hit.prim, w);
            const double u = hit.u, v = hit.v;
            sp.p = Vec3f(w[0] * (1.0 - u - v) + w[1] * u + w[2] * v);
            if (!cfg.smooth_normals) sp.p_shadow = sp.p;
            sp.ng = Vec3f(normalize(cross(w[1] - w[0], w[2] - w[0])));
        }
        const ShadingFrame frame = shading_frame(sp, cam_ray.dir);  // as shade() spawns its rays
        const bool front = frame.front;
        const Vec3f Ng = frame.Ng;
        const double u_p = double(ulp(max_abs(sp.p)));
        const double u_offset = double(ulp(std::max(max_abs(sp.p), sp.offset_scale)));  // ray_offset.h's unit
        const Vec3d n_exact = exact_normal(Vec3d(sp.p), hit);
        res.point_error_ulps.push_back(std::fabs(surface_distance(Vec3d(sp.p), hit)) / u_p);
        res.normal_error_rad.push_back(angle_between(Vec3d(sp.ng), n_exact));

        // The hit point in double, before SceneView rounds it (the double-origin experiment).
        Vec3d p_double = Vec3d(sp.p);
        if (cfg.double_origin_ulps >= 0.0) {
            if (analytic) {
                p_double = centre + normalize(Vec3d(cam_ray.org) + Vec3d(cam_ray.dir) * double(hit.t) - centre) * s;
            } else {
                Vec3d w[3];
                scene.world_triangle(0, hit.prim, w);
                p_double = w[0] * (1.0 - double(hit.u) - double(hit.v)) + w[1] * double(hit.u) + w[2] * double(hit.v);
            }
        }
        for (int kind = 0; kind < 3; ++kind) {
            const bool inward = kind == 1;
            const Vec3f base = kind == 2 && front ? sp.p_shadow : sp.p;
            Vec3f org = offset(base, sp.offset_scale, inward ? -Ng : Ng);
            if (cfg.double_origin_ulps >= 0.0 && !(kind == 2 && cfg.smooth_normals)) {
                const Vec3d nd = Vec3d(inward ? -Ng : Ng);
                const Vec3d od = p_double + nd * (cfg.double_origin_ulps * u_offset);
                for (int k = 0; k < 3; ++k) {
                    org[k] = float(od[k]);
                    if ((double(org[k]) - od[k]) * nd[k] < 0.0) org[k] = detail::step_towards(org[k], float(nd[k]));
                }
            }
            const double dist = surface_distance(Vec3d(org), hit) / u_offset * (inward ? -1.0 : 1.0);
            if (kind < 2 || !cfg.smooth_normals) {  // lifted shadow origins are not offsets
                res.max_offset_ulps = std::max(res.max_offset_ulps, std::fabs(dist));
                res.min_offset_ulps = std::min(res.min_offset_ulps, dist);
            }
            for (int j = 0; j < cfg.directions; ++j) {
                const Vec3d dir_d = hemisphere_direction(inward ? -n_exact : n_exact, j, rng);
                Ray r;
                r.org = org;
                r.dir = Vec3f(dir_d);
                // The integrator only spawns rays on the correct side of its float Ng.
                const float side = dot(r.dir, Ng);
                if (inward ? !(side < 0.f) : !(side > 0.f)) {
                    ++res.normal_disagreements;
                    continue;
                }
                ++res.rays[kind];
                // The skip-origin experiment: repeat a query that found the origin's own
                // primitive from just beyond it (for the analytic sphere, only its root at the
                // origin: an inward ray's far side is a true hit).
                auto query = [&](Ray q, RayKind rk) {
                    Hit h = accel->intersect(q, rk);
                    for (int retry = 0; cfg.skip_origin && retry < 4 && h.valid() && filter.is_a(h) && h.prim == hit.prim &&
                                        (!analytic || double(h.t) < s * std::fabs(dot(dir_d, n_exact)));
                         ++retry) {
                        q.tnear = std::nextafter(h.t, kInfinity);
                        h = accel->intersect(q, rk);
                    }
                    return h;
                };
                if (kind == 2 && cfg.skip_origin) {
                    const bool checked = std::fabs(dot(dir_d, n_exact)) >= cfg.neighbour_min_cos;
                    if (!checked) ++res.neighbour_unchecked;
                    const Hit h = query(r, RayKind::Reflection);
                    if (h.valid() && filter.is_a(h)) ++res.self_hits[kind];
                    else if (checked && (!h.valid() || crossing_side(r, h) != 1)) ++res.neighbour_misses[kind];
                    continue;
                }
                if (kind == 2) {
                    const bool checked = std::fabs(dot(dir_d, n_exact)) >= cfg.neighbour_min_cos;
                    if (!checked) ++res.neighbour_unchecked;
                    r.tfar = float(4.0 * s);
                    const Color tr = accel->transmittance(r);
                    if (tr.x == 0.f) ++res.self_hits[kind];
                    else if (tr.x == 0.25f) ++res.shadow_double_counts;  // B's crossing counted twice
                    else if (tr.x != 0.5f && checked) ++res.neighbour_misses[kind];
                    continue;
                }
                // Below cos 1e-3 the crossing of a neighbour a few ulps away moves along the ray by
                // (point error) / cos: only self-hits are judged for those rays.
                bool neighbour_checked = std::fabs(dot(dir_d, n_exact)) >= cfg.neighbour_min_cos;
                if (!neighbour_checked) ++res.neighbour_unchecked;
                if (inward && !has_inner && neighbour_checked) {
                    ++res.neighbour_unreachable;
                    neighbour_checked = false;
                }
                if (inward && analytic && neighbour_checked) {
                    // A grazing inward ray can skim through the shell between A and C and leave A
                    // again without reaching C (exact geometry, from the float origin): no neighbour.
                    double c0, c1, a0, a1;
                    const bool reaches_c = sphere_roots<double>(Vec3d(r.org), Vec3d(r.dir), centre, s * (1.0 - d), c0, c1) && c0 > 0.0;
                    const bool exits_a_first = sphere_roots<double>(Vec3d(r.org), Vec3d(r.dir), centre, s, a0, a1) && reaches_c && a1 < c0;
                    // Near-tangent to C (closest approach margin (r^2 - p^2) / r^2 < 1e-3) the
                    // float sphere kernel's roots are ill-conditioned (docs/accelerators.md).
                    const Vec3d f = Vec3d(r.org) - centre;
                    const double rc = s * (1.0 - d), along = dot(f, Vec3d(r.dir)) / dot(Vec3d(r.dir), Vec3d(r.dir));
                    const Vec3d perp = f - Vec3d(r.dir) * along;
                    const bool tangent = (rc * rc - dot(perp, perp)) / (rc * rc) < 1e-3;
                    if (!reaches_c || exits_a_first || tangent) {
                        ++res.neighbour_unreachable;
                        neighbour_checked = false;
                    }
                }
                const Hit h = query(r, inward ? RayKind::Refraction : RayKind::Reflection);
                if (h.valid() && filter.is_a(h)) {
                    // Outward rays can never meet the convex A again. Inward rays of the closed
                    // sphere reach A's far side just behind C (within a few ulps of t: a tie, not
                    // a self-intersection); near an edge of the tessellation an inward grazing
                    // ray may also leave through the adjacent facet, which exact geometry confirms.
                    const double chord = 2.0 * s * std::fabs(dot(dir_d, n_exact));
                    bool exact_crossing = false;
                    if (!analytic && h.prim != hit.prim) {
                        Vec3d w[3];
                        scene.world_triangle(0, h.prim, w);
                        const Vec3d nh = cross(w[1] - w[0], w[2] - w[0]);
                        exact_crossing = dot(Vec3d(r.org) - w[0], nh) * dot(dir_d, nh) < 0.0;
                    }
                    if (inward && !quad && double(h.t) > 0.5 * chord) ++res.far_side_ties;
                    else if (inward && exact_crossing) ++res.edge_exits;
                    else ++res.self_hits[kind];
                } else if (neighbour_checked && (!h.valid() || crossing_side(r, h) != (inward ? -1 : 1))) {
                    ++res.neighbour_misses[kind];
                }
            }
        }
    }
    if (res.min_offset_ulps == 1e300) res.min_offset_ulps = 0;
    return res;
}

// ---------------------------------------------------------------------------------------------
// 3. Watertightness

namespace {

/// Distance from p to the triangle (a, b, c) (Ericson, Real-Time Collision Detection, 5.1.5).
double point_triangle_distance(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    const Vec3d ab = b - a, ac = c - a, ap = p - a;
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return length(p - a);
    const Vec3d bp = p - b;
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return length(p - b);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return length(p - (a + ab * (d1 / (d1 - d3))));
    const Vec3d cp = p - c;
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return length(p - c);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return length(p - (a + ac * (d2 / (d2 - d6))));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        return length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
    const double denom = 1.0 / (va + vb + vc);
    return length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

/// Counts crossings of the ray (o, d) with the mesh in double (Möller-Trumbore, no tolerance).
int crossings(const Mesh& m, const Vec3d& o, const Vec3d& d) {
    int n = 0;
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
        const Vec3d a(m.positions[m.indices[t]]), b(m.positions[m.indices[t + 1]]), c(m.positions[m.indices[t + 2]]);
        const Vec3d e1 = b - a, e2 = c - a, pv = cross(d, e2);
        const double det = dot(e1, pv);
        if (det == 0.0) continue;
        const Vec3d tv = o - a;
        const double u = dot(tv, pv) / det;
        const Vec3d qv = cross(tv, e1);
        const double v = dot(d, qv) / det, tt = dot(e2, qv) / det;
        if (u >= 0 && v >= 0 && u + v <= 1 && tt > 0) ++n;
    }
    return n;
}

}  // namespace

bool find_inside_point(const Mesh& m, Vec3f& inside, float& radius) {
    Bounds3d box;
    for (const Vec3f& p : m.positions) box.extend(Vec3d(p));
    std::mt19937_64 rng(11);
    for (int attempt = 0; attempt < 200; ++attempt) {
        const double spread = 0.3 * attempt / 200.0;
        std::uniform_real_distribution<double> u(0.5 - spread, 0.5 + spread);
        const Vec3d c = box.lo + box.diagonal() * Vec3d(u(rng), u(rng), u(rng));
        bool odd = true;
        for (int k = 0; k < 3 && odd; ++k) odd = crossings(m, c, random_unit(rng)) % 2 == 1;
        if (!odd) continue;
        double dist = 1e300;
        for (size_t t = 0; t + 2 < m.indices.size(); t += 3)
            dist = std::min(dist, point_triangle_distance(c, Vec3d(m.positions[m.indices[t]]),
                                                          Vec3d(m.positions[m.indices[t + 1]]),
                                                          Vec3d(m.positions[m.indices[t + 2]])));
        if (dist < 1e-3 * max_component(box.diagonal())) continue;
        inside = Vec3f(c);
        radius = float(0.5 * dist);
        return true;
    }
    return false;
}

WatertightResult probe_watertight(const Mesh& mesh_in, const Vec3f& inside, float inside_radius,
                                  const WatertightConfig& cfg) {
    const ScopedFlushDenormals ftz;  // as the renderer traces (render.cpp); the caller's mode after
    Scene scene;
    const uint32_t mat = add_material(scene);
    Mesh mesh = mesh_in;
    mesh.material = mat;
    scene.meshes.push_back(std::move(mesh));
    const Mat4d xf = placement(cfg.scale, cfg.translation);
    add_instance(scene, 0, xf);
    OpaqueFilter filter;
    const auto accel = create_accelerator(cfg.accel, scene, filter, AccelConfig{cfg.robust, cfg.threads});
    const Mesh& m = scene.meshes[0];

    constexpr uint64_t kChunk = 4096;
    const uint64_t chunks = (cfg.rays + kChunk - 1) / kChunk;
    std::atomic<uint64_t> rays[3] = {0, 0, 0}, leaks[3] = {0, 0, 0};
    const auto start = std::chrono::steady_clock::now();
    tbb::task_arena arena(cfg.threads > 0 ? cfg.threads : tbb::this_task_arena::max_concurrency());
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint64_t>(0, chunks), [&](const tbb::blocked_range<uint64_t>& range) {
            const ScopedFlushDenormals ftz;  // as the renderer traces (render.cpp)
            for (uint64_t c = range.begin(); c != range.end(); ++c) {
                std::mt19937_64 rng(cfg.seed * 0x9E3779B97F4A7C15ull + c);
                std::uniform_real_distribution<double> u01(0.0, 1.0);
                uint64_t local_rays[3] = {0, 0, 0}, local_leaks[3] = {0, 0, 0};
                const uint64_t n = std::min(kChunk, cfg.rays - c * kChunk);
                for (uint64_t i = 0; i < n; ++i) {
                    const int kind = int((c * kChunk + i) % 3);
                    const Vec3d o_obj = Vec3d(inside) + random_unit(rng) * (double(inside_radius) * u01(rng));
                    const uint32_t prim = uint32_t(u01(rng) * double(m.triangle_count())) % uint32_t(m.triangle_count());
                    Vec3d v[3];
                    for (int k = 0; k < 3; ++k) v[k] = Vec3d(m.positions[m.indices[size_t(prim) * 3 + size_t(k)]]);
                    Vec3d aim;
                    const int k = int(u01(rng) * 3.0) % 3;
                    if (kind == int(AimKind::Vertex)) {
                        aim = v[k];
                    } else if (kind == int(AimKind::EdgeMidpoint)) {
                        aim = (v[k] + v[(k + 1) % 3]) * 0.5;
                    } else {
                        double a = u01(rng), b = u01(rng);
                        if (a + b > 1.0) a = 1.0 - a, b = 1.0 - b;
                        aim = v[0] * (1.0 - a - b) + v[1] * a + v[2] * b;
                    }
                    const Vec3d o = xf.apply_point(o_obj), t = xf.apply_point(aim);
                    Ray r;
                    r.org = Vec3f(o);
                    r.dir = Vec3f(normalize(t - Vec3d(r.org)));
                    ++local_rays[kind];
                    if (!accel->intersect(r, RayKind::Reflection).valid()) ++local_leaks[kind];
                }
                for (int k = 0; k < 3; ++k) rays[k] += local_rays[k], leaks[k] += local_leaks[k];
            }
        });
    });
    WatertightResult res;
    for (int k = 0; k < 3; ++k) res.rays[k] = rays[k], res.leaks[k] = leaks[k];
    res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return res;
}

// ---------------------------------------------------------------------------------------------
// 7. Hit-point error

HitErrorResult probe_hit_error(const std::string& accel_name, bool sphere, double s, double translation, size_t n,
                               uint64_t seed) {
    const ScopedFlushDenormals ftz;  // as the renderer traces (render.cpp); the caller's mode after
    Scene scene;
    const uint32_t mat = add_material(scene);
    const Vec3d centre = kTranslationDir * translation;
    if (sphere) {
        Sphere sp;
        sp.center = centre;
        sp.radius = s;
        sp.material = mat;
        scene.spheres.push_back(sp);
    } else {
        Mesh mesh = make_closed_sphere(24, 48, false);
        mesh.material = mat;
        scene.meshes.push_back(std::move(mesh));
        add_instance(scene, 0, placement(s, translation));
    }
    OpaqueFilter filter;
    const SceneView view(scene, MappingOptions{});
    const auto accel = create_accelerator(accel_name, scene, filter);
    const auto ref = create_accelerator("bvh:precision=double", scene, filter);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    HitErrorResult res;
    for (size_t i = 0; i < n; ++i) {
        // From 3 radii away, aimed at a random point of the disc facing it.
        const Vec3d from = random_unit(rng);
        Vec3d t, b;
        frame(from, t, b);
        const double rr = std::sqrt(u01(rng)), ph = 2.0 * kPiD * u01(rng);
        const Vec3d aim = centre + (t * std::cos(ph) + b * std::sin(ph)) * (rr * s);
        Ray r;
        r.org = Vec3f(centre + from * (3.0 * s));
        r.dir = Vec3f(normalize(aim - Vec3d(r.org)));
        ++res.rays;
        const Hit hf = accel->intersect(r, RayKind::Camera), hd = ref->intersect(r, RayKind::Camera);
        if (hf.valid() != hd.valid()) {
            ++res.miss_mismatch;
            continue;
        }
        if (!hf.valid()) continue;
        if (hf.prim != hd.prim) {
            ++res.different_prim;  // an edge: both are right within rounding, the points are compared anyway
        }
        // Exact point on the double path's primitive, in double.
        const Vec3d o(r.org), d(r.dir);
        Vec3d exact;
        if (sphere) {
            double t0, t1;
            if (!sphere_roots<double>(o, d, centre, s, t0, t1)) continue;
            exact = o + d * (t0 > 0.0 ? t0 : t1);
        } else {
            Vec3d w[3];
            scene.world_triangle(0, hd.prim, w);
            const Vec3d n = cross(w[1] - w[0], w[2] - w[0]);
            exact = o + d * (dot(w[0] - o, n) / dot(d, n));
        }
        ++res.both_hit;
        const Vec3f p = view.surface(r, hf).p;
        const Vec3d e = Vec3d(p) - exact;
        const double err = std::max({std::fabs(e.x), std::fabs(e.y), std::fabs(e.z)});
        const double mag = std::max({std::fabs(exact.x), std::fabs(exact.y), std::fabs(exact.z)});
        res.rel_error.push_back(err / mag);
        res.ulp_error.push_back(err / double(ulp(float(mag))));
    }
    return res;
}

// ---------------------------------------------------------------------------------------------
// 8. Analytic quadrics

QuadricProbeResult probe_quadric(const QuadricProbeConfig& cfg) {
    const ScopedFlushDenormals ftz;  // as the renderer traces (render.cpp); the caller's mode after
    Scene scene;
    const uint32_t mat = add_material(scene);
    // Object space (make_quadric's): base at z = 0, top at z = h = 2 (the cone: radius 1 to 0.4), or
    // a unit disc at z = 0.
    const bool disc = cfg.kind == QuadricKind::Disc;
    const double r0 = 1.0, r1 = cfg.kind == QuadricKind::Cone ? 0.4 : 1.0;
    Quadric q = make_quadric(cfg.kind, {0, 0, disc ? 0.0 : -1.0}, {0, 0, 1}, r0, r1, !disc,
                             placement(cfg.scale, cfg.translation));
    q.material = mat;
    scene.quadrics.push_back(q);
    scene.cameras.push_back(Camera{});
    OpaqueFilter filter;
    const SceneView view(scene, MappingOptions{});
    const auto accel = create_accelerator(cfg.accel, scene, filter);
    const RayOffsetPolicy policy = accel->ray_offset();
    const QuadricShape shape(q);
    const Mat4d& m = q.world_from_object;
    // Exact outward normal of the object-space point x (on the surface) in world space.
    auto exact_normal = [&](const Vec3d& x, int part) {
        const double k = (q.radius1 - q.radius0) / q.height;
        const double r = q.radius0 + k * x.z;
        const Vec3d n = disc ? Vec3d{0, 0, 1} : part == 1 ? Vec3d{0, 0, -1} : part == 2 ? Vec3d{0, 0, 1} : Vec3d{x.x, x.y, -k * r};
        return normalize(q.object_from_world.transposed().apply_vector(n));
    };
    std::mt19937_64 rng(cfg.seed);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    QuadricProbeResult res;
    const double h = 2.0;
    const double side_area = disc ? 0.0 : kPiD * (r0 + r1) * std::sqrt(h * h + (r0 - r1) * (r0 - r1));
    const double cap_area = disc ? kPiD : kPiD * (r0 * r0 + r1 * r1);
    for (size_t i = 0; i < cfg.points; ++i) {
        // A point of A in object space: a quarter on a rim, the rest area-uniform.
        const double phi = 2.0 * kPiD * u01(rng);
        const Vec3d radial{std::cos(phi), std::sin(phi), 0.0};
        Vec3d x;
        int part = 0;
        if (disc) {
            x = radial * (i % 4 == 0 ? r0 : r0 * std::sqrt(u01(rng)));
        } else if (i % 4 == 0) {
            const bool top = i % 8 == 0;
            x = radial * (top ? r1 : r0) + Vec3d{0, 0, top ? h : 0.0};
            part = u01(rng) < 0.5 ? 0 : (top ? 2 : 1);  // which face's normal the ray arrives against
        } else if (u01(rng) * (side_area + cap_area) < side_area) {
            const double z = h * u01(rng);
            x = radial * (r0 + (r1 - r0) * z / h) + Vec3d{0, 0, z};
        } else {
            const bool top = u01(rng) * (r0 * r0 + r1 * r1) < r1 * r1;
            x = radial * ((top ? r1 : r0) * std::sqrt(u01(rng))) + Vec3d{0, 0, top ? h : 0.0};
            part = top ? 2 : 1;
        }
        const Vec3d target = m.apply_point(x);
        const Vec3d n_target = exact_normal(x, part);
        // A camera ray from outside, at any cosine down to grazing (discs: either side).
        const Vec3d face = disc && (i & 1) ? -n_target : n_target;
        const Vec3d from = hemisphere_direction(face, int(i), rng);
        Ray cam;
        cam.org = Vec3f(target + from * (2.0 * cfg.scale));
        cam.dir = Vec3f(-from);
        double te[2];
        uint8_t fe[2];
        const int ne = quadric_crossings(shape, Vec3d(cam.org), Vec3d(cam.dir), te, fe);
        const Hit hit = accel->intersect(cam, RayKind::Camera);
        if (ne == 0 || !(te[0] > 0.0)) {  // the float ray passes the rim outside: nothing to judge
            continue;
        }
        if (!hit.valid()) {
            ++res.camera_misses;
            continue;
        }
        ++res.points;
        const SurfacePoint sp = view.surface(cam, hit);
        const Vec3d exact = Vec3d(cam.org) + Vec3d(cam.dir) * te[0];
        // Along the surface the error is the float t's (the point is moved onto the surface, not
        // along it): in ulps of the larger of the point and the distance the ray travelled.
        const double mag = std::max(max_abs(exact), te[0] * length(Vec3d(cam.dir)));
        res.point_error_ulps.push_back(max_abs(Vec3d(sp.p) - exact) / double(ulp(float(mag))));
        res.surface_error_ulps.push_back(max_abs(quadric_point(q, Vec3d(sp.p), fe[0]).p - Vec3d(sp.p)) /
                                         double(ulp(float(max_abs(Vec3d(sp.p))))));
        const QuadricPoint qp = quadric_point(q, exact, fe[0]);
        // Distance of the exact point from the nearest rim (world), for the inward rays below.
        double rim_distance = std::numeric_limits<double>::infinity();
        if (!disc) {
            const Vec3d xo = q.object_from_world.apply_point(exact);
            const double rho = std::hypot(xo.x, xo.y);
            const Vec3d dir_xy = rho > 0.0 ? Vec3d{xo.x / rho, xo.y / rho, 0.0} : Vec3d{1.0, 0.0, 0.0};
            for (const Vec3d rim : {dir_xy * r0, dir_xy * r1 + Vec3d{0, 0, h}})
                rim_distance = std::min(rim_distance, length(m.apply_point(rim) - exact));
        }
        res.normal_error_rad.push_back(angle_between(Vec3d(sp.ng), qp.n));
        const ShadingFrame frame = shading_frame(sp, cam.dir);
        for (int kind = 0; kind < 3; ++kind) {
            const bool inward = kind == 1;
            if (inward && disc) continue;  // a disc has no inside
            const Vec3f org = policy.origin(kind == 2 && frame.front ? sp.p_shadow : sp.p, sp.offset_scale,
                                            inward ? -frame.Ng : frame.Ng);
            for (int j = 0; j < cfg.directions; ++j) {
                const Vec3d nd = Vec3d(inward ? -frame.Ng : frame.Ng);
                Ray r;
                r.org = org;
                r.dir = Vec3f(hemisphere_direction(normalize(nd), j, rng));
                if (inward ? !(dot(r.dir, frame.Ng) < 0.f) : !(dot(r.dir, frame.Ng) > 0.f)) continue;
                ++res.rays[kind];
                if (kind == 2) {
                    r.tfar = float(8.0 * cfg.scale);
                    if (accel->transmittance(r).x == 0.f) ++res.self_hits[kind];
                    continue;
                }
                const Hit h = accel->intersect(r, inward ? RayKind::Refraction : RayKind::Reflection);
                if (!inward) {
                    if (h.valid()) ++res.self_hits[kind];  // A is convex: an outward ray never meets it again
                    continue;
                }
                // Inward: the far side, from the exact point along the same direction. Not judged
                // where the origin's offset cannot resolve the solid: within 16 offsets of a rim (the
                // origin may round out through the other face) or a chord shorter than that.
                double tf[2];
                uint8_t ff[2];
                const int nf = quadric_crossings(shape, exact, Vec3d(r.dir), tf, ff);
                const double far = nf == 2 ? tf[1] : 0.0;
                const double reach = 16.0 * length(Vec3d(org) - Vec3d(sp.p));
                if (rim_distance < reach || far * length(Vec3d(r.dir)) < reach) {
                    ++res.inward_unjudged;
                    continue;
                }
                if (!h.valid()) {
                    if (far > 0.0) ++res.leaks;  // left the solid without meeting it
                } else if (double(h.t) < 0.5 * far) {
                    ++res.self_hits[kind];
                }
            }
        }
    }
    // From inside, exactly at the rims (object space, then the world).
    if (!disc) {
        const Vec3d inside = m.apply_point({0, 0, 1});  // the middle of the axis
        for (size_t i = 0; i < cfg.points; ++i) {
            const double phi = 2.0 * kPiD * u01(rng);
            const bool top = i & 1;
            const Vec3d rim = m.apply_point(Vec3d{std::cos(phi), std::sin(phi), 0.0} * (top ? r1 : r0) + Vec3d{0, 0, top ? 2.0 : 0.0});
            Ray r;
            r.org = Vec3f(inside);
            r.dir = Vec3f(rim - Vec3d(r.org));
            ++res.rim_rays;
            if (!accel->intersect(r, RayKind::Reflection).valid()) ++res.leaks;
        }
    }
    return res;
}

// ---------------------------------------------------------------------------------------------
// 2. Scale and translation invariance

void transform_scene(Scene& scene, double s, double t) {
    // World-space checkers are anchored at the world origin: the translation is snapped to a
    // multiple of their period (2 squares) so the pattern lands on the same points.
    Vec3d shift = kTranslationDir * t;
    for (const Texture& tex : scene.textures)
        if (tex.kind == TextureKind::Checker && tex.checker.world_space) {
            const double period = 2.0 * double(tex.checker.size) * s;
            for (int k = 0; k < 3; ++k) shift[k] = std::round(shift[k] / period) * period;
        }
    const Mat4d m = Mat4d::translate(shift) * Mat4d::scale(Vec3d(s));
    for (Instance& in : scene.instances) in.world_from_object = m * in.world_from_object;
    for (Sphere& sp : scene.spheres) {
        sp.center = m.apply_point(sp.center);
        sp.radius *= s;
    }
    for (Quadric& q : scene.quadrics) {
        q.world_from_object = m * q.world_from_object;
        q.object_from_world = q.world_from_object.inverse_affine();
    }
    for (Plane& p : scene.planes) p.point = m.apply_point(p.point);
    for (Light& l : scene.lights) {
        l.position = m.apply_point(l.position);
        if (l.type != LightType::Directional) {
            if (l.attenuation == Attenuation::InverseSquare) l.intensity = float(double(l.intensity) * s * s);
            if (l.attenuation == Attenuation::Classic) {
                l.classic_c.y = float(double(l.classic_c.y) / s);
                l.classic_c.z = float(double(l.classic_c.z) / (s * s));
            }
            l.range = float(double(l.range) * s);
        }
    }
    for (Camera& c : scene.cameras) {
        c.world_from_camera = m * c.world_from_camera;
        c.xmag *= s;
        c.ymag *= s;
        c.znear *= s;
        c.zfar *= s;
    }
    for (Material& mat : scene.materials) {
        mat.classic.absorption = mat.classic.absorption * float(1.0 / s);
        mat.thickness = float(double(mat.thickness) * s);
        mat.attenuation_distance = float(double(mat.attenuation_distance) * s);
    }
    for (Texture& tex : scene.textures)
        if (tex.kind == TextureKind::Checker && tex.checker.world_space) tex.checker.size = float(double(tex.checker.size) * s);
}

double psnr(const Film& a, const Film& b) {
    double peak = 1.0, se = 0.0;
    for (const Color& c : b.beauty) peak = std::max({peak, double(c.x), double(c.y), double(c.z)});
    for (size_t i = 0; i < a.beauty.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            const double d = double(a.beauty[i][k]) - double(b.beauty[i][k]);
            se += d * d;
        }
    const double mse = se / double(3 * a.beauty.size());
    return mse > 0.0 ? 10.0 * std::log10(peak * peak / mse) : 999.0;
}

double max_abs_diff(const Film& a, const Film& b, double tol, size_t* bad_pixels) {
    double worst = 0.0;
    size_t bad = 0;
    for (size_t i = 0; i < a.beauty.size(); ++i) {
        double px = 0.0;
        for (int k = 0; k < 3; ++k) px = std::max(px, std::fabs(double(a.beauty[i][k]) - double(b.beauty[i][k])));
        if (!(px <= tol)) ++bad;
        worst = std::max(worst, px);
    }
    if (bad_pixels) *bad_pixels = bad;
    return worst;
}

size_t nonfinite_values(const Film& film) {
    size_t n = 0;
    for (const Color& c : film.beauty) n += !is_finite(c);
    return n;
}

// ---------------------------------------------------------------------------------------------
// 4. Energy bound

namespace {

/// The integrator's ray tree with the local model replaced by its bound: shadows and cosines at
/// 1, every light counted. Orientation, directions and offsets come from the integrator's own
/// helpers (shading_frame.h, src/shading/optics.h), so only the tree's shape is written twice.
class BoundTracer {
public:
    BoundTracer(const SceneView& view, const Accelerator& accel, const IntegratorSettings& s)
        : m_view(view), m_accel(accel), m_offset(accel.ray_offset()), m_s(s), m_covers(OpaqueCovers::find(view)) {}

    Color trace(const Ray& ray, RayKind kind, int depth, const RayCone& cone, float weight) const {
        Hit hit = m_accel.intersect(ray, kind);
        if (!hit.valid()) return m_s.background;
        const Scene& scene = m_view.scene();
        SurfacePoint sp = m_view.surface(ray, hit, cone);
        // shade()'s rule: an opaque surface under a transmissive one lying on it is what the ray sees
        // (a glass resting on a floor), so the tree does not pass through the floor below it.
        if (m_covers && m_covers->candidate(object_index(scene, hit.geom, hit.inst))) {
            RayCounters unused;
            Hit cover = m_covers->at(sp.p, sp.offset_scale, sp.ng, unused);
            if (cover.valid()) {
                cover.t = hit.t;
                hit = cover;
                sp = m_view.surface(ray, hit, cone);
            }
        }
        const RayCone secondary{cone.width_at(hit.t), cone.spread};
        const Material& mat = scene.materials[sp.material];
        const WhittedCoeffs c = m_view.coefficients(sp);
        const ShadingFrame frame = shading_frame(sp, ray.dir);  // shade()'s orientation rule
        const Vec3f V = frame.V, Ng = frame.Ng, N = frame.N;
        const bool front = frame.front;
        Color result = c.emission;
        const bool unlit = mat.model == MaterialModel::GltfPbr && mat.unlit;
        if (!unlit) {
            result += m_s.ambient * c.ka;
            if (!is_black(c.kd) || !is_black(c.ks))
                for (const Light& light : scene.lights) result += sample_light(light, sp.p).intensity * (c.kd + c.ks);
            if (depth < m_s.max_depth) {
                auto [kr, kt] = secondary_weights(c.ks, c.kr, c.kt, std::clamp(dot(N, V), 0.f, 1.f), m_s.fresnel);
                const float wt = weight * max_component(kt);
                if (!is_black(kt) && wt >= m_s.min_weight) {
                    const auto dir = transmitted_direction(ray.dir, N, Ng, front ? 1.f / c.ior : c.ior, c.thin);
                    if (dir) {
                        const Ray t = spawn_ray(m_offset, sp, -Ng, *dir);
                        result += kt * trace(t, RayKind::Refraction, depth + 1, secondary, wt);
                    } else {
                        kr += kt;  // total internal reflection
                    }
                }
                const float wr = weight * max_component(kr);
                if (!is_black(kr) && wr >= m_s.min_weight) {
                    const Ray r = spawn_ray(m_offset, sp, Ng, mirror_direction(V, N, Ng));
                    result += kr * trace(r, RayKind::Reflection, depth + 1, secondary, wr);
                }
            }
        }
        if (!front && !c.thin && !is_black(c.absorption))
            for (int i = 0; i < 3; ++i) result[i] *= std::exp(-c.absorption[i] * hit.t);
        if (mat.model == MaterialModel::GltfPbr && mat.alpha_mode == AlphaMode::Blend) {
            const float alpha = std::clamp(m_view.material_inputs(mat, sp).base_color.w, 0.f, 1.f);
            if (alpha < 1.f) {
                const Ray behind = spawn_ray(m_offset, sp, -Ng, ray.dir);
                const Color b = depth < m_s.max_depth
                                    ? trace(behind, RayKind::Refraction, depth + 1, secondary, weight * (1.f - alpha))
                                    : m_s.background;
                result = result * alpha + b * (1.f - alpha);
            }
        }
        return result;
    }

private:
    const SceneView& m_view;
    const Accelerator& m_accel;
    RayOffsetPolicy m_offset;  ///< m_accel's, as the integrator keeps it
    IntegratorSettings m_s;
    std::shared_ptr<const OpaqueCovers> m_covers;  ///< as the integrator finds them (null: none)
};

}  // namespace

EnergyResult check_energy_bound(const Scene& scene, const RenderSettings& settings_in) {
    const ScopedFlushDenormals ftz;  // as the renderer traces (render.cpp); the caller's mode after
    RenderSettings settings = settings_in;
    settings.aa = AaSettings{};  // pixel centres: one camera ray per pixel, the one the bound follows
    const Renderer renderer(scene, settings);
    const Film film = renderer.render();
    const ImageSize size = renderer.image_size();
    const CameraModel camera(scene.cameras[size_t(settings.camera)], size.width, size.height);
    const BoundTracer tracer(renderer.view(), renderer.accelerator(), settings.integrator);
    EnergyResult res;
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            const Color v = film.beauty[film.index(x, y)];
            ++res.pixels;
            if (!is_finite(v)) {
                ++res.nonfinite;
                continue;
            }
            const Color b = tracer.trace(camera.generate(x + 0.5, y + 0.5), RayKind::Camera, 0, camera.pixel_cone(), 1.f) *
                            settings.exposure;
            bool over = false;
            for (int k = 0; k < 3; ++k) {
                const double bk = std::max(0.0, double(b[k]));
                if (double(v[k]) > bk * (1.0 + 1e-4) + 1e-6) over = true;
                if (bk > 1e-6) res.worst_ratio = std::max(res.worst_ratio, double(v[k]) / bk);
            }
            res.over_bound += over;
        }
    return res;
}

}  // namespace whitted::stress
