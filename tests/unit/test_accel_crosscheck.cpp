// Every in-house backend against the brute-force oracle, hit for hit: random and edge-case rays
// over procedural meshes, instances, analytic spheres and infinite planes, and a real glTF asset;
// filter semantics (accept() cut-outs, transparent shadows with de-duplication) for every kind of
// geometry; degenerate inputs; the float-vs-double t error of triangles and spheres.
//
// Tolerance: the in-house backends share the oracle's watertight triangle test and object-space
// transform, so the same primitive must come with the same t to 1e-6 relative. Where the closest
// primitive differs, the hit is accepted as a tie only if both t agree to 1e-6 relative (shared
// edges and vertices, where either triangle is a correct answer); ties are counted and printed.
#include <gtest/gtest.h>

#include <random>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>

#include "accel/factory/create_accelerator.h"
#include "importers/scene_loader.h"
#include "accel/bvh/bvh_accel.h"
#include "accel/bvh/wide_bvh.h"
#include "core/error.h"
#include "tests/support/test_accel_util.h"

namespace whitted {
namespace {

using namespace whitted::test;

constexpr float kRelTol = 1e-6f;

const std::vector<std::string>& fast_backends() {
    // "bvh" is the wide BVH (wide_bvh.h: 8-wide with AVX2, else 4-wide); width=2 the binary tree.
    static const std::vector<std::string> names{"bvh", "bvh:width=2", "bvh:width=4", "bvh:bv=sphere", "kdop", "grid",
                                                "octree"};
    return names;
}

/// Other settings of the same backends, checked on the Duck only (to keep the suite fast).
const std::vector<std::string>& variant_backends() {
    static const std::vector<std::string> names{"bvh:bins=8,leaf=2", "bvh:width=8,isa=sse2",
                                                "bvh:leaf=64,intersection_cost=0.1",
                                                "grid:lambda=1", "octree:leaf=4,depth=6"};
    return names;
}

/// A sphere, a triangle soup, a terrain, the sphere instanced again under a rotation and
/// non-uniform scale, a mirrored box; mesh indices chosen so PatternFilter covers opaque, cut-out
/// and transparent meshes.
Scene mixed_scene() {
    Scene s;
    add_mesh_instance(s, make_uv_sphere({0, 0, 0}, 1.f, 24, 48));                       // 0 opaque
    add_mesh_instance(s, make_soup(3000, 7, 2.f, 0.15f));                                // 1 cut-out
    add_mesh_instance(s, make_terrain(40, 0.3f), Mat4d::translate({0, 0, -1.5}));         // 2 transparent
    Mat4d xf = Mat4d::translate({2.5, 0.5, 0}) * Mat4d::rotate(0.2, 0.4, 0.1, 0.888819) * Mat4d::scale({1, 0.5, 2});
    add_instance(s, 0, xf);                                                              // mesh 0 again
    add_mesh_instance(s, make_uv_sphere({0, 0, 0}, 0.5f, 6, 8),
                      Mat4d::translate({-2.5, 0, 0}) * Mat4d::scale({-1, 1, 1}));         // 3 cut-out, mirrored
    add_mesh_instance(s, make_terrain(8, 0.0f), Mat4d::translate({0, 0, 2}));              // 4 (flat, opaque)
    add_mesh_instance(s, make_uv_sphere({0, 0, 0}, 0.7f, 12, 12), Mat4d::translate({0, 2, 0}));  // 5 transparent
    return s;
}

struct CheckResult {
    size_t rays = 0, ties = 0, differ = 0;
};

/// The oracle's answers for a ray set, computed once: closest hits, the same rays again with
/// tfar set exactly to the oracle's hit (the hit lies in (tnear, tfar], so it must be found),
/// and transmittance along segments.
struct Reference {
    std::vector<Ray> rays, shadow_rays;
    std::vector<Hit> hits;
    std::vector<Color> transmittance;

    Reference(const Accelerator& oracle, const std::vector<Ray>& input) {
        for (const Ray& r : input) {
            const Hit h = oracle.intersect(r, RayKind::Camera);
            rays.push_back(r);
            hits.push_back(h);
            if (h.valid()) {
                Ray clipped = r;
                clipped.tfar = h.t;
                rays.push_back(clipped);
                hits.push_back(oracle.intersect(clipped, RayKind::Camera));
            }
            Ray segment = r;
            segment.tfar = 1.f;  // the segment from the origin to the target point
            shadow_rays.push_back(segment);
            transmittance.push_back(oracle.transmittance(segment));
        }
    }
};

CheckResult check_closest(const Accelerator& accel, const Reference& ref) {
    CheckResult r;
    for (size_t i = 0; i < ref.rays.size(); ++i) {
        const Hit got = accel.intersect(ref.rays[i], RayKind::Camera);
        const Agreement a = compare_hits(got, ref.hits[i], kRelTol);
        if (a == Agreement::Differ && r.differ < 3) {  // enough to reproduce the first disagreements
            const Ray& ray = ref.rays[i];
            std::printf("  differ: org (%.9g, %.9g, %.9g) dir (%.9g, %.9g, %.9g) t [%.9g, %.9g]: got t %.9g geom %u "
                        "inst %u prim %u, oracle t %.9g geom %u inst %u prim %u\n",
                        ray.org.x, ray.org.y, ray.org.z, ray.dir.x, ray.dir.y, ray.dir.z, ray.tnear, ray.tfar, got.t,
                        got.geom, got.inst, got.prim, ref.hits[i].t, ref.hits[i].geom, ref.hits[i].inst,
                        ref.hits[i].prim);
            Ray open = ray;
            open.tfar = kInfinity;
            const Hit h = accel.intersect(open, RayKind::Camera);
            std::printf("  same ray with tfar = inf: t %.9g geom %u inst %u prim %u\n", h.t, h.geom, h.inst, h.prim);
        }
        ++r.rays;
        r.ties += a == Agreement::Tie;
        r.differ += a == Agreement::Differ;
    }
    return r;
}

size_t check_transmittance(const Accelerator& accel, const Reference& ref, float tol) {
    size_t bad = 0;
    for (size_t i = 0; i < ref.shadow_rays.size(); ++i) {
        const Color a = accel.transmittance(ref.shadow_rays[i]), b = ref.transmittance[i];
        for (int k = 0; k < 3; ++k) bad += std::fabs(a[k] - b[k]) > tol * std::max(1e-3f, std::fabs(b[k])) ? 1 : 0;
    }
    return bad;
}

void run_all(const Scene& scene, const SurfaceFilter& filter, uint32_t ray_count, const char* label,
             bool variants = false, const std::vector<Ray>& extra_rays = {}) {
    std::vector<Ray> rays = make_rays(scene, ray_count, 1234);
    rays.insert(rays.end(), extra_rays.begin(), extra_rays.end());
    const Reference ref(*create_accelerator("brute", scene, filter), rays);
    std::vector<std::string> names = fast_backends();
    if (variants) names.insert(names.end(), variant_backends().begin(), variant_backends().end());
    for (const std::string& name : names) {
        SCOPED_TRACE(name);
        const auto accel = create_accelerator(name, scene, filter);
        const CheckResult r = check_closest(*accel, ref);
        std::printf("[ %s ] %-24s %zu rays: %zu differ, %zu ties (accepted: equal t, other primitive)\n", label,
                    name.c_str(), r.rays, r.differ, r.ties);
        EXPECT_EQ(r.differ, 0u);
        EXPECT_EQ(check_transmittance(*accel, ref, 1e-6f), 0u);
    }
    // The double-precision BVH against the double-precision oracle.
    const Reference ref_d(*create_accelerator("brute:precision=double", scene, filter), rays);
    const auto bvh_d = create_accelerator("bvh:precision=double", scene, filter);
    const CheckResult r = check_closest(*bvh_d, ref_d);
    std::printf("[ %s ] %-24s %zu rays: %zu differ, %zu ties\n", label, "bvh:precision=double", r.rays, r.differ, r.ties);
    EXPECT_EQ(r.differ, 0u);
    EXPECT_EQ(check_transmittance(*bvh_d, ref_d, 1e-6f), 0u);
}

// embree:flatten=1 (experimental) puts the meshes one instance uses into the top level in world
// space: on random rays, the same closest hits as the instanced build (ties allowed) up to float
// rounding of the transformed vertices, on a scene with a shared, a mirrored (kept instanced) and
// filtered meshes, and the same transmittance; a bad value is one clear error. make_rays' rays
// aimed exactly at vertices and edge midpoints are counted, not bounded: there the two
// arithmetics may decide an edge differently (as any two Embree builds of other coordinates).
/// `flat_spec` against `instanced_spec` on mixed_scene (see above): closest hits and
/// transmittance agree on all but one in a thousand random rays.
void expect_flattened_matches_instanced(const std::string& flat_spec, const std::string& instanced_spec) {
    const Scene s = mixed_scene();
    const PatternFilter filter;
    constexpr uint32_t kRandom = 2000;  // make_rays' first kRandom rays are random segments
    const std::vector<Ray> rays = make_rays(s, kRandom, 99);
    // ROBUST, as the renderer builds Embree by default.
    const auto instanced = create_accelerator(instanced_spec, s, filter, AccelConfig{true});
    const auto flat = create_accelerator(flat_spec, s, filter, AccelConfig{true});
    EXPECT_NE(flat->stats().bytes, instanced->stats().bytes) << flat_spec << ": nothing was flattened";
    size_t differ = 0, ties = 0, hits = 0, edge_differ = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        const Hit a = flat->intersect(rays[i], RayKind::Camera), b = instanced->intersect(rays[i], RayKind::Camera);
        // Rays that start on a surface hit it again at t ~ 0 or not, depending on the rounding
        // of the space they are intersected in: the renderer never casts those (its origins are
        // offset). Compared beyond t = 1e-5 (the scene's extent is ~5).
        constexpr float kOnSurface = 1e-5f;
        if ((a.valid() && a.t < kOnSurface) || (b.valid() && b.t < kOnSurface)) continue;
        const Agreement g = compare_hits(a, b, 1e-4f);
        if (i >= kRandom) {
            edge_differ += g == Agreement::Differ;
            continue;
        }
        if (g == Agreement::Differ)
            std::printf("  differ: flat t %.7g g%u i%u p%u | inst t %.7g g%u i%u p%u\n", a.t, a.geom, a.inst, a.prim, b.t,
                        b.geom, b.inst, b.prim);
        differ += g == Agreement::Differ;
        ties += g == Agreement::Tie;
        hits += b.valid();
    }
    std::printf("[ %s ] %u random rays, %zu hits: %zu differ, %zu ties; vertex/edge rays: %zu differ of %zu\n",
                flat_spec.c_str(), kRandom, hits, differ, ties, edge_differ, rays.size() - kRandom);
    EXPECT_GT(hits, kRandom / 4);
    EXPECT_LE(differ * 1000, size_t(kRandom)) << flat_spec;
    size_t shadow_differ = 0;
    for (size_t i = 0; i < kRandom; ++i) {
        Ray ray = rays[i];
        ray.tnear = std::max(ray.tnear, 1e-5f);  // not from on a surface (see above)
        const Color a = flat->transmittance(ray), b = instanced->transmittance(ray);
        shadow_differ += std::fabs(a.x - b.x) > 1e-4f || std::fabs(a.y - b.y) > 1e-4f || std::fabs(a.z - b.z) > 1e-4f;
    }
    EXPECT_LE(shadow_differ * 1000, size_t(kRandom)) << flat_spec;
}

TEST(AccelCrossCheck, EmbreeFlattenedMatchesInstanced) {
    expect_flattened_matches_instanced("embree:flatten=1", "embree:flatten=0");
    EXPECT_THROW(create_accelerator("embree:flatten=2", mixed_scene(), PatternFilter{}), Error);
}

// The in-house BVH's flat BLAS (common/two_level.h) in each of its forms: 8- and 4-wide, binary;
// and against the double-precision structures, which never flatten.
TEST(AccelCrossCheck, BvhFlattenedMatchesInstanced) {
    expect_flattened_matches_instanced("bvh:flatten=1", "bvh:flatten=0");
    expect_flattened_matches_instanced("bvh:flatten=1,width=4", "bvh:flatten=0,width=4");
    expect_flattened_matches_instanced("bvh:flatten=1,width=2", "bvh:flatten=0,width=2");
    expect_flattened_matches_instanced("bvh", "bvh:precision=double");
    EXPECT_THROW(create_accelerator("bvh:flatten=yes", mixed_scene(), PatternFilter{}), Error);
}

TEST(AccelCrossCheck, MixedSceneOpaque) {
    const Scene s = mixed_scene();
    run_all(s, OpaqueFilter{}, 500, "mixed/opaque");
}

TEST(AccelCrossCheck, MixedSceneWithFilters) {
    const Scene s = mixed_scene();
    run_all(s, PatternFilter{}, 500, "mixed/filter");
}

TEST(AccelCrossCheck, DuckAsset) {
    ImportOptions io;
    io.load_textures = false;
    const Scene s = load_scene(WHITTED_ASSETS_DIR "/gltf/Duck/glTF-Binary/Duck.glb", io);
    ASSERT_GT(s.instanced_triangle_count(), 1000u);
    run_all(s, OpaqueFilter{}, 600, "Duck", true);
}

TEST(AccelCrossCheck, BundledDefaultScene) {
    ImportOptions io;
    io.load_textures = false;
    const Scene s = load_scene(WHITTED_ASSETS_DIR "/scenes/default.glb", io);
    run_all(s, PatternFilter{}, 250, "default.glb");
}

// ---- analytic spheres and infinite planes ----

void add_sphere(Scene& s, Vec3d c, double r) { s.spheres.push_back({c, r, 0, "s" + std::to_string(s.spheres.size())}); }
void add_plane(Scene& s, Vec3d p, Vec3d n, Vec3d u) { s.planes.push_back({p, n, u, 0, "p" + std::to_string(s.planes.size())}); }

/// Triangles and instances (as mixed_scene, smaller) with spheres and planes. Sphere kinds under
/// MixedFilter go by index % 4 (opaque, transparent, cut away, entering side cut away), plane
/// kinds by index % 3 (opaque, transparent, checker cut-out).
Scene analytic_scene() {
    Scene s;
    add_mesh_instance(s, make_uv_sphere({0, 0, 0}, 1.f, 16, 24));                        // mesh 0 opaque
    add_mesh_instance(s, make_soup(800, 11, 2.f, 0.15f));                                // mesh 1 cut-out
    add_mesh_instance(s, make_terrain(16, 0.3f), Mat4d::translate({0, 0, -1.5}));         // mesh 2 transparent
    add_instance(s, 0, Mat4d::translate({2.5, 0.5, 0}) * Mat4d::rotate(0.2, 0.4, 0.1, 0.888819) * Mat4d::scale({1, 0.5, 2}));
    add_sphere(s, {1.2, 0.4, 0.2}, 0.8);       // 0 opaque, cuts into the mesh sphere
    add_sphere(s, {-2, 1, 0}, 1.0);            // 1 transparent, outermost of a nested triple
    add_sphere(s, {-2, 1, 0}, 0.5);            // 2 cut away, concentric inside it
    add_sphere(s, {-2.2, 1.1, 0.1}, 0.2);      // 3 entering side cut away, inside both
    add_sphere(s, {0, -2, 0}, 0.7);            // 4 opaque, overlapping the next
    add_sphere(s, {0.5, -2, 0.2}, 0.6);        // 5 transparent
    add_sphere(s, {0.3, 0.2, -1.4}, 0.4);      // 6 cut away, through the terrain
    add_sphere(s, {2, -2, 1}, 1e-3);           // 7 tiny, entering side cut away
    add_sphere(s, {2.5, 0.5, 0}, 0.3);         // 8 opaque, inside the scaled instance
    std::mt19937 rng(99);
    std::uniform_real_distribution<double> pos(-2.5, 2.5), rad(0.05, 0.3);
    for (int i = 0; i < 24; ++i) add_sphere(s, {pos(rng), pos(rng), pos(rng)}, rad(rng));
    add_plane(s, {0, -3, 0}, {0, 1, 0}, {1, 0, 0});                                    // opaque floor
    const Vec3d n = normalize(Vec3d(1, 2, 3));
    add_plane(s, {0, 0, 0.5}, n, normalize(cross(n, Vec3d(0, 0, 1))));                  // transparent, tilted
    add_plane(s, {2.8, 0, 0}, {-1, 0, 0}, {0, 0, 1});                                   // checker cut-out
    return s;
}

TEST(AccelCrossCheck, AnalyticSceneOpaque) {
    const Scene s = analytic_scene();
    run_all(s, OpaqueFilter{}, 300, "analytic/opaque", false, make_analytic_rays(s, 4, 17));
}

/// Embree (user-geometry spheres and quadrics, planes beside it) against the brute-force oracle
/// on random rays and `extra`: its triangle test is not watertight, so rays aimed exactly at
/// vertices and edges (make_rays' edge cases) are left to test_accel_embree; here analytic hits
/// must agree exactly, and triangle hits up to rare ties. Embree's triangle t is less exact than
/// the watertight one (~1e-6 of the coordinates' magnitude, which is a large relative error for
/// the short hits of rays starting next to a mesh): a distance tolerance of 2e-6 of the scene
/// size applies to triangle hits.
void expect_embree_matches_brute(const Scene& s, const SurfaceFilter& filter, const std::vector<Ray>& extra,
                                 const char* label) {
    const double tol = 2e-6 * length(s.world_bounds().diagonal());
    std::vector<Ray> rays = make_rays(s, 300, 1234);
    rays.resize(300);
    rays.insert(rays.end(), extra.begin(), extra.end());
    const auto brute = create_accelerator("brute", s, filter);
    const auto embree = create_accelerator("embree", s, filter);
    size_t differ = 0, analytic_differ = 0, bad_tr = 0;
    for (Ray r : rays) {
        const Hit e = embree->intersect(r, RayKind::Camera), b = brute->intersect(r, RayKind::Camera);
        const bool near = e.valid() && b.valid() && std::fabs(double(e.t) - double(b.t)) * length(Vec3d(r.dir)) <= tol &&
                          s.geom_kind(e.geom) == GeomKind::Mesh && s.geom_kind(b.geom) == GeomKind::Mesh;
        if (!near && compare_hits(e, b, kRelTol) == Agreement::Differ) {
            ++differ;
            const bool tri_e = e.valid() && s.geom_kind(e.geom) == GeomKind::Mesh;
            const bool tri_b = b.valid() && s.geom_kind(b.geom) == GeomKind::Mesh;
            analytic_differ += !tri_e && !tri_b;
        }
        r.tfar = 1.f;
        const Color te = embree->transmittance(r), tb = brute->transmittance(r);
        for (int k = 0; k < 3; ++k) bad_tr += std::fabs(te[k] - tb[k]) > 1e-5f * std::max(1e-3f, std::fabs(tb[k]));
    }
    std::printf("[ %s ] %-24s %zu rays: %zu differ (%zu with neither answer a triangle), %zu transmittance "
                "channel mismatches\n", label, "embree", rays.size(), differ, analytic_differ, bad_tr);
    EXPECT_EQ(analytic_differ, 0u);
    EXPECT_LE(double(differ), 0.002 * double(rays.size()));
    EXPECT_LE(double(bad_tr), 0.002 * double(rays.size()));
}

TEST(AccelCrossCheck, AnalyticSceneWithFilters) {
    const Scene s = analytic_scene();
    const MixedFilter filter(s);
    const std::vector<Ray> extra = make_analytic_rays(s, 4, 18);
    run_all(s, filter, 300, "analytic/filter", false, extra);
    expect_embree_matches_brute(s, filter, extra, "analytic/filter");
}

// ---- analytic quadrics (cylinders, cones, discs) beside meshes, spheres and a plane ----

void add_quadric(Scene& s, QuadricKind kind, Vec3d base, Vec3d apex, double r0, double r1, bool caps,
                 const Mat4d& xf = Mat4d::identity(), double inner = 0.0) {
    Quadric q = make_quadric(kind, base, apex, r0, r1, caps, xf);
    q.inner_radius = inner;
    q.name = "q" + std::to_string(s.quadrics.size());
    s.quadrics.push_back(q);
}

Scene quadric_scene() {
    using K = QuadricKind;
    Scene s;
    add_mesh_instance(s, make_uv_sphere({0, 0, 0}, 1.f, 16, 24));                     // mesh 0
    add_mesh_instance(s, make_terrain(16, 0.3f), Mat4d::translate({0, 0, -1.5}));      // mesh 1
    add_sphere(s, {1.2, 0.4, 0.2}, 0.8);
    add_sphere(s, {-2, 1, 0}, 0.6);
    add_quadric(s, K::Cylinder, {-2, -1, 0}, {-2, 2, 0}, 0.7, 0.7, true);              // 0 opaque, capped, through sphere 1
    add_quadric(s, K::Cylinder, {1, -2, -1}, {2, -1, 1}, 0.3, 0.3, false);             // 1 transparent, open, tilted
    add_quadric(s, K::Cylinder, {2, 1, 0}, {2, 2.5, 0}, 0.5, 0.5, true);               // 2 cut on leaving, capped
    add_quadric(s, K::Cone, {0, 1.5, -1}, {0, 2.8, -1}, 0.9, 0.2, true);               // 3 opaque truncated cone
    add_quadric(s, K::Cone, {-1, -2.5, 1}, {-1, -1, 1.5}, 0.6, 0.0, false);            // 4 transparent, open, to a point
    add_quadric(s, K::Cone, {0.5, 0, 2}, {0.5, 0, 0.5}, 0.0, 0.8, true);               // 5 cut, apex first
    add_quadric(s, K::Disc, {0, -2.9, 0}, {0, -1.9, 0}, 1.5, 1.5, false);              // 6 opaque disc on the floor
    add_quadric(s, K::Disc, {-1, 0, 1.5}, {0, 1, 2.5}, 1.0, 1.0, false, Mat4d::identity(), 0.4);  // 7 transparent annulus
    // 8 cut: an elliptic cylinder (non-uniform scale after a rotation), mirrored
    add_quadric(s, K::Cylinder, {0, 0, 0}, {0, 0, 1}, 0.5, 0.5, true,
                Mat4d::translate({-0.5, 0.5, -2}) * Mat4d::scale({-1.5, 0.6, 1}) * Mat4d::rotate(0.3, 0.1, 0.2, 0.927362));
    add_quadric(s, K::Cylinder, {1.6, 0.4, 0.2}, {0.8, 0.4, 0.2}, 0.2, 0.2, true);     // 9 opaque, through sphere 0
    add_quadric(s, K::Cone, {-2, 1, 0}, {-2, 1.6, 0}, 0.6, 0.3, true);                 // 10 transparent, on sphere 1
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> pos(-2.5, 2.5), rad(0.05, 0.3);
    for (int i = 0; i < 18; ++i) {
        const Vec3d b{pos(rng), pos(rng), pos(rng)}, a = b + Vec3d{pos(rng), pos(rng), pos(rng)} * 0.3;
        add_quadric(s, K(i % 3), b, a, rad(rng), i % 2 ? rad(rng) : 0.0, i % 4 != 0);
    }
    add_plane(s, {0, -3, 0}, {0, 1, 0}, {1, 0, 0});
    return s;
}

TEST(AccelCrossCheck, QuadricSceneOpaque) {
    const Scene s = quadric_scene();
    run_all(s, OpaqueFilter{}, 400, "quadric/opaque", false, make_analytic_rays(s, 6, 21));
}

TEST(AccelCrossCheck, QuadricSceneWithFilters) {
    const Scene s = quadric_scene();
    const MixedFilter filter(s);
    const std::vector<Ray> extra = make_analytic_rays(s, 6, 22);
    run_all(s, filter, 400, "quadric/filter", false, extra);
    expect_embree_matches_brute(s, filter, extra, "quadric/filter");
}

/// Filter for closed-form transmittance: every sphere Kt 0.5, every plane Kt 0.8.
class HalfGlass final : public SurfaceFilter {
public:
    explicit HalfGlass(uint32_t first_plane) : m_first_plane(first_plane) {}
    bool accept(const Ray&, const Hit&, RayKind) const override { return true; }
    Color transmittance(const Ray&, const Hit& h) const override { return Color(h.geom >= m_first_plane ? 0.8f : 0.5f); }
    uint32_t mesh_flags(uint32_t) const override { return kNeedsTransmittance; }

private:
    uint32_t m_first_plane;
};

/// Closed forms: nested transparent spheres count in and out once each; a tiny sphere far away
/// still counts twice although both roots lie within the de-duplication window; a ray from the
/// common centre exits the inner sphere first.
TEST(AccelAnalytic, NestedAndTinyTransparentSpheres) {
    Scene s;
    add_sphere(s, {0, 0, 10}, 2.0);          // geom 0
    add_sphere(s, {0, 0, 10}, 1.0);          // geom 1, nested
    add_sphere(s, {0, 0, 1e4}, 1e-4);        // geom 2, tiny and far: chord 2e-4 < 64 ulps of 1e4
    add_plane(s, {0, 0, 5}, {0, 0, 1}, {1, 0, 0});  // geom 3
    const HalfGlass filter(s.plane_geom_id(0));
    for (const std::string& name : accelerator_names()) {
        SCOPED_TRACE(name);
        const auto accel = create_accelerator(name, s, filter);
        Ray r;
        r.dir = {0, 0, 1};
        r.tfar = 100.f;
        EXPECT_FLOAT_EQ(accel->transmittance(r).x, 0.8f * 0.0625f);   // plane, then 4 sphere crossings
        r.tfar = 2e4f;
        EXPECT_FLOAT_EQ(accel->transmittance(r).x, 0.8f * 0.0625f * 0.25f);
        r.org = {0, 0, 10};
        r.tfar = 100.f;
        EXPECT_FLOAT_EQ(accel->transmittance(r).x, 0.25f);            // from the centre: out of both
        const Hit h = accel->intersect(r, RayKind::Camera);
        EXPECT_EQ(h.geom, 1u);
        EXPECT_FLOAT_EQ(h.t, 1.f);
        r.org = {0, 0, 9990};
        r.tfar = kInfinity;
        const Hit tiny = accel->intersect(r, RayKind::Camera);
        EXPECT_EQ(tiny.geom, 2u);
        EXPECT_NEAR(tiny.t, 10.f - 1e-4f, 1e-5f);
    }
}

/// Float against double (bvh against bvh:precision=double, the same rays and hits) over
/// triangles (object-space test after the instance transform) and spheres: the relative t error
/// of hits on the same primitive. Figures quoted in docs/accelerators.md.
TEST(AccelPrecision, FloatVsDoubleTError) {
    ImportOptions io;
    io.load_textures = false;
    std::vector<std::pair<const char*, Scene>> scenes;
    scenes.emplace_back("mixed", mixed_scene());
    scenes.emplace_back("analytic", analytic_scene());
    scenes.emplace_back("Duck", load_scene(WHITTED_ASSETS_DIR "/gltf/Duck/glTF-Binary/Duck.glb", io));
    OpaqueFilter filter;
    std::vector<double> tri, sph, sph_edge;
    for (const auto& [label, s] : scenes) {
        const auto f = create_accelerator("bvh", s, filter), d = create_accelerator("bvh:precision=double", s, filter);
        // Random rays and the analytic edge cases (tangent rays, rays from sphere centres and
        // surfaces, ...). Hits within 1e-4 of the scene size from the origin are left out: a ray
        // starting on a surface re-hits it at t ~ 1e-8 in float and ~1e-17 in double, where a
        // relative error means nothing (that is the ray-offset problem, not precision of t).
        std::vector<Ray> rays = make_rays(s, 3000, 4321);
        rays.resize(3000);
        const std::vector<Ray> extra = make_analytic_rays(s, 20, 5);
        rays.insert(rays.end(), extra.begin(), extra.end());
        const double min_dist = 1e-4 * length(s.world_bounds().diagonal());
        for (size_t i = 0; i < rays.size(); ++i) {
            const Ray& r = rays[i];
            const Hit a = f->intersect(r, RayKind::Camera), b = d->intersect(r, RayKind::Camera);
            if (!a.valid() || !b.valid() || a.geom != b.geom || a.inst != b.inst || a.prim != b.prim) continue;
            if (double(std::min(a.t, b.t)) * length(Vec3d(r.dir)) < min_dist) continue;
            // Hit::t is float: the double path's t rounded once, so errors below half an ulp of
            // float vanish (common for spheres; the kernel test resolves them).
            const double err = std::fabs(double(a.t) - double(b.t)) / double(b.t);
            if (s.geom_kind(a.geom) == GeomKind::Mesh) tri.push_back(err);
            else (i < 3000 ? sph : sph_edge).push_back(err);
        }
    }
    auto figures = [](std::vector<double> e, const char* what, double max_bound) {
        ASSERT_GT(e.size(), 500u) << what;
        std::sort(e.begin(), e.end());
        const double med = e[e.size() / 2], p99 = e[e.size() * 99 / 100], mx = e.back();
        std::printf("[ precision ] %-26s float vs double t, same primitive: %5zu hits, median %.2e, p99 %.2e, max %.2e\n",
                    what, e.size(), med, p99, mx);
        EXPECT_LE(med, 1e-7) << what;
        EXPECT_LE(mx, max_bound) << what;
    };
    figures(tri, "triangles (random rays)", 1e-4);
    figures(sph, "spheres (random rays)", 1e-5);
    // Tangent rays are ill-conditioned: t moves by ~sqrt(eps) of the radius.
    figures(sph_edge, "spheres (analytic edge rays)", 1e-2);
}

/// A closed mesh must not leak: rays from inside a sphere towards random directions always hit
/// (pbrt's Triangle.Watertight idea), for every backend.
TEST(AccelCrossCheck, WatertightClosedMesh) {
    Scene s;
    add_mesh_instance(s, make_uv_sphere({0.1f, -0.2f, 0.3f}, 1.f, 32, 64));
    OpaqueFilter filter;
    std::mt19937 rng(5);
    std::normal_distribution<float> g;
    for (const std::string& name : fast_backends()) {
        const auto accel = create_accelerator(name, s, filter);
        size_t misses = 0;
        for (int i = 0; i < 3000; ++i) {
            Ray r;
            r.org = {0.1f, -0.2f, 0.3f};
            // Also through vertices: direction straight at one.
            r.dir = i % 3 == 0 ? s.meshes[0].positions[size_t(i) % s.meshes[0].positions.size()] - r.org
                               : Vec3f(g(rng), g(rng), g(rng));
            misses += !accel->intersect(r, RayKind::Camera).valid();
        }
        EXPECT_EQ(misses, 0u) << name;
    }
}

/// Each transparent crossing counts once: two coincident copies of one transparent quad in one
/// mesh are one crossing (de-duplicated); two instances of it are two crossings.
TEST(AccelCrossCheck, TransmittanceDeduplication) {
    Scene s;
    Mesh quad;
    quad.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    quad.indices = {0, 1, 2, 0, 2, 3, 0, 1, 2};  // first triangle twice
    quad.normals.assign(4, Vec3f(0, 0, 1));
    s.meshes.push_back(quad);
    s.meshes.push_back(quad);
    s.meshes.push_back(quad);
    add_instance(s, 2);                                    // mesh 2: transparent (Kt 0.9, ., 0.5)
    add_instance(s, 2, Mat4d::translate({0, 0, 1}));       // a second crossing
    PatternFilter filter;
    Ray r;
    r.org = {0.5f, -0.5f, -1.f};  // through the duplicated triangle
    r.dir = {0.f, 0.f, 1.f};
    r.tfar = 10.f;
    const Color one = filter.transmittance(r, Hit{1.f, 0, 0, 0, 2, 0});
    for (const std::string& name : accelerator_names()) {
        const auto accel = create_accelerator(name, s, filter);
        const Color tr = accel->transmittance(r);
        EXPECT_NEAR(tr.x, one.x * one.x, 1e-6f) << name;
        EXPECT_NEAR(tr.y, one.y * one.y, 1e-6f) << name;
        EXPECT_NEAR(tr.z, one.z * one.z, 1e-6f) << name;
        // Through the shared diagonal edge: still one crossing per quad.
        Ray edge = r;
        edge.org = {0.25f, 0.25f, -1.f};
        const Color te = accel->transmittance(edge);
        EXPECT_NEAR(te.y, one.y * one.y, 1e-6f) << name;
    }
}

// ---- degenerate input: no crash, no endless loop, sensible answers ----

void expect_sane(const Scene& s, const char* what) {
    OpaqueFilter filter;
    std::vector<Ray> rays;
    if (!s.instances.empty() && s.instanced_triangle_count() > 0) rays = make_rays(s, 200, 9);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    Ray bad;
    bad.dir = {nan, 1, 0};
    rays.push_back(bad);
    bad.dir = {0, 0, 0};
    rays.push_back(bad);
    bad.org = {nan, nan, nan};
    bad.dir = {0, 0, 1};
    rays.push_back(bad);
    bad.org = {0, 0, -5};
    bad.tnear = nan;
    rays.push_back(bad);
    bad.tnear = 2.f;
    bad.tfar = 1.f;
    rays.push_back(bad);
    const auto oracle = create_accelerator("brute", s, filter);
    for (const std::string& name : accelerator_names()) {
        SCOPED_TRACE(std::string(what) + " / " + name);
        const auto start = std::chrono::steady_clock::now();
        const auto accel = create_accelerator(name, s, filter);
        for (size_t i = 0; i < rays.size(); ++i) {
            const Hit h = accel->intersect(rays[i], RayKind::Camera);
            const bool traceable = ray_is_traceable(rays[i]);
            if (!traceable) {
                EXPECT_FALSE(h.valid()) << "ray " << i;
            } else if (name != "embree") {
                EXPECT_NE(compare_hits(h, oracle->intersect(rays[i], RayKind::Camera), kRelTol), Agreement::Differ)
                    << "ray " << i;
            }
            (void)accel->transmittance(rays[i]);
        }
        EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
    }
}

// ray_is_traceable is branch-free arithmetic; it must say what its definition says for every
// mix of finite, zero, tiny, huge, infinite and NaN fields.
TEST(AccelDegenerate, RayIsTraceableFollowsItsDefinition) {
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    const float specials[] = {0.f, -0.f, 1.f, -2.5f, 1e-40f, -1e-45f, 3e38f, -3e38f, inf, -inf, nan};
    auto definition = [](const Ray& r) {
        return std::isfinite(r.org.x) && std::isfinite(r.org.y) && std::isfinite(r.org.z) && std::isfinite(r.dir.x) &&
               std::isfinite(r.dir.y) && std::isfinite(r.dir.z) &&
               (r.dir.x != 0.f || r.dir.y != 0.f || r.dir.z != 0.f) && std::isfinite(r.tnear) && !std::isnan(r.tfar) &&
               r.tnear <= r.tfar;
    };
    size_t checked = 0, traceable = 0;
    auto check = [&](const Ray& r) {
        const bool expected = definition(r);
        ASSERT_EQ(ray_is_traceable(r), expected)
            << "org " << r.org.x << " " << r.org.y << " " << r.org.z << " dir " << r.dir.x << " " << r.dir.y << " "
            << r.dir.z << " t " << r.tnear << " " << r.tfar;
        ++checked;
        traceable += expected;
    };
    // Every pair of the eight fields takes every pair of special values, the others plain.
    for (int a = 0; a < 8; ++a)
        for (int b = a; b < 8; ++b)
            for (const float va : specials)
                for (const float vb : specials) {
                    float f[8] = {0.5f, -1.f, 2.f, 0.f, 0.f, 1.f, 0.f, inf};
                    f[a] = va;
                    f[b] = vb;
                    check(Ray{{f[0], f[1], f[2]}, {f[3], f[4], f[5]}, f[6], f[7]});
                }
    // The direction's three components over all specials (zero and tiny lengths).
    for (const float x : specials)
        for (const float y : specials)
            for (const float z : specials) check(Ray{{0.f, 0.f, 0.f}, {x, y, z}, 0.f, 10.f});
    EXPECT_GT(traceable, checked / 10);
    EXPECT_LT(traceable, checked);
}

TEST(AccelDegenerate, EmptyScene) {
    expect_sane(Scene{}, "empty");
    Scene s;
    s.meshes.push_back(Mesh{});
    add_instance(s, 0);
    expect_sane(s, "empty mesh");
}

TEST(AccelDegenerate, OneTriangle) {
    Scene s;
    Mesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    m.indices = {0, 1, 2};
    add_mesh_instance(s, m);
    expect_sane(s, "one triangle");
}

TEST(AccelDegenerate, AllTrianglesAtOnePoint) {
    Scene s;
    Mesh m;
    m.positions = {{1, 2, 3}};
    for (int i = 0; i < 3000; ++i) m.indices.insert(m.indices.end(), {0, 0, 0});
    add_mesh_instance(s, m);
    Mesh line;  // and triangles collapsed to a segment
    line.positions = {{0, 0, 0}, {1, 1, 1}};
    for (int i = 0; i < 500; ++i) line.indices.insert(line.indices.end(), {0, 1, 1});
    add_mesh_instance(s, line);
    expect_sane(s, "one point");
}

/// A hit at a tiny t from an origin far (relatively) from the world origin, on a flat floor whose
/// box has zero thickness, with tfar exactly at the hit: the triangle's t carries an error of
/// order eps * |p - o| / |d|, far more than eps * t, and no culling test may drop that box
/// (SlabRay::cull_slack).
TEST(AccelCrossCheck, TinyTHitWithTfarExactlyAtTheHit) {
    Scene s;
    Mesh floor;
    floor.positions = {{-40, 0.25f, -40}, {40, 0.25f, -40}, {40, 0.25f, 40}, {-40, 0.25f, 40}};
    floor.indices = {0, 2, 1, 0, 3, 2};
    add_mesh_instance(s, floor);
    add_mesh_instance(s, floor, Mat4d::translate({3.0, 7.0, -5.0}));  // one behind a transform too
    const OpaqueFilter filter;
    const auto oracle = create_accelerator("brute", s, filter);
    std::mt19937 rng(99);
    std::uniform_real_distribution<float> pos(-30.f, 30.f), height(1e-5f, 1e-2f), dir(-4.f, 4.f);
    std::vector<Ray> rays;
    for (int i = 0; i < 20000; ++i) {
        Ray r;
        const float base = (i & 1) ? 0.25f : 7.25f;
        r.org = {pos(rng) + ((i & 1) ? 0.f : 3.f), base + height(rng), pos(rng) - ((i & 1) ? 0.f : 5.f)};
        r.dir = {dir(rng), -std::abs(dir(rng)) - 0.05f, dir(rng)};
        const Hit h = oracle->intersect(r, RayKind::Camera);
        if (!h.valid()) continue;
        r.tfar = h.t;
        rays.push_back(r);
    }
    ASSERT_GT(rays.size(), 15000u);
    for (const std::string& name : fast_backends()) {
        SCOPED_TRACE(name);
        const auto accel = create_accelerator(name, s, filter);
        size_t missed = 0;
        for (const Ray& r : rays) missed += accel->intersect(r, RayKind::Camera).valid() ? 0 : 1;
        EXPECT_EQ(missed, 0u) << name << " of " << rays.size();
    }
}

TEST(AccelDegenerate, HugeNextToTiny) {
    Scene s;
    Mesh m = make_soup(2000, 3, 1.f, 1e-4f);
    const uint32_t base = uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), {{-1e6f, -1e6f, 0.5f}, {1e6f, -1e6f, 0.5f}, {0, 1e6f, 0.5f}});
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
    add_mesh_instance(s, m);
    expect_sane(s, "huge+tiny");
}

/// Spheres and planes that cannot be hit (NaN or infinite centre, radius 0, negative, NaN or
/// infinite; a plane with a zero or NaN normal) are left out everywhere; valid ones still work.
TEST(AccelDegenerate, InvalidSpheresAndPlanes) {
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    Scene s;
    add_sphere(s, {nan, 0, 5}, 1.0);
    add_sphere(s, {inf, 0, 5}, 1.0);
    add_sphere(s, {0, 0, 5}, 0.0);
    add_sphere(s, {0, 0, 5}, -1.0);
    add_sphere(s, {0, 0, 5}, nan);
    add_sphere(s, {0, 0, 5}, inf);
    add_sphere(s, {0, 0, 8}, 1.0);     // geom 6: the valid one
    add_plane(s, {0, 0, 2}, {0, 0, 0}, {1, 0, 0});
    add_plane(s, {nan, 0, 2}, {0, 0, 1}, {1, 0, 0});
    add_plane(s, {0, 0, 20}, {0, 0, 1}, {1, 0, 0});  // geom 9: the valid one
    OpaqueFilter filter;
    for (const std::string& name : accelerator_names()) {
        SCOPED_TRACE(name);
        const auto accel = create_accelerator(name, s, filter);
        Ray r;
        r.dir = {0, 0, 1};
        Hit h = accel->intersect(r, RayKind::Camera);
        EXPECT_EQ(h.geom, 6u);
        EXPECT_FLOAT_EQ(h.t, 7.f);
        r.org = {5, 0, 0};
        h = accel->intersect(r, RayKind::Camera);
        EXPECT_EQ(h.geom, 9u);
        EXPECT_FLOAT_EQ(h.t, 20.f);
        r.tfar = 19.f;
        EXPECT_EQ(accel->transmittance(r).x, 1.f);
        r.dir = {0, 0, 0};
        EXPECT_FALSE(accel->intersect(r, RayKind::Camera).valid());
        EXPECT_EQ(accel->transmittance(r).x, 1.f);
    }
}

// ---- the wide BVH against the binary one it is collapsed from ----

/// Bit patterns of a hit's floats, to assert exact equality (not within a tolerance).
bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// The wide BVH's triangle test runs the watertight test's operations in the same order on four
/// lanes, and its node test culls nothing the binary one keeps: every hit must be bit for bit the
/// binary tree's (t, u, v), and where the primitive differs (a tie at a shared edge, found in
/// another order) t must be the same float. The AVX2 and SSE2 traversals must agree entirely.
void expect_wide_equals_binary(const Scene& s, const SurfaceFilter& filter, const std::vector<Ray>& rays,
                               const char* label) {
    const auto binary = create_accelerator("bvh:width=2", s, filter);
    for (const char* name :
         {"bvh", "bvh:width=8", "bvh:width=4", "bvh:width=8,isa=sse2", "bvh:leaf=64,intersection_cost=0.1"}) {
        SCOPED_TRACE(std::string(label) + " / " + name);
        const auto wide = create_accelerator(name, s, filter);
        size_t ties = 0, bad = 0, bad_tr = 0;
        for (const Ray& r : rays) {
            const Hit a = wide->intersect(r, RayKind::Camera), b = binary->intersect(r, RayKind::Camera);
            if (a.valid() != b.valid() || !same_bits(a.t, b.t)) {
                ++bad;
            } else if (a.valid() && (a.prim != b.prim || a.geom != b.geom || a.inst != b.inst)) {
                ++ties;
            } else if (a.valid() && (!same_bits(a.u, b.u) || !same_bits(a.v, b.v))) {
                ++bad;
            }
            Ray seg = r;
            seg.tfar = 1.f;
            const Color ta = wide->transmittance(seg), tb = binary->transmittance(seg);
            bad_tr += same_bits(ta.x, tb.x) && same_bits(ta.y, tb.y) && same_bits(ta.z, tb.z) ? 0 : 1;
        }
        std::printf("[ %s ] %-36s %zu rays: %zu not bit-identical, %zu ties, %zu transmittances differ\n", label, name,
                    rays.size(), bad, ties, bad_tr);
        EXPECT_EQ(bad, 0u);
        EXPECT_EQ(bad_tr, 0u);
    }
    // Same tree, same order: the AVX2 (where the CPU has it) and SSE2 code paths give identical
    // records.
    const auto avx = create_accelerator("bvh:width=8", s, filter);
    const auto sse = create_accelerator("bvh:width=8,isa=sse2", s, filter);
    size_t differ = 0;
    for (const Ray& r : rays) {
        const Hit a = avx->intersect(r, RayKind::Camera), b = sse->intersect(r, RayKind::Camera);
        differ += std::memcmp(&a, &b, sizeof a) == 0 ? 0 : 1;
    }
    EXPECT_EQ(differ, 0u) << label << ": isa=auto vs isa=sse2";
}

TEST(AccelWideBvh, BitIdenticalToBinaryTree) {
    const Scene mixed = mixed_scene();
    std::vector<Ray> rays = make_rays(mixed, 2000, 77);
    expect_wide_equals_binary(mixed, PatternFilter{}, rays, "mixed");
    ImportOptions io;
    io.load_textures = false;
    const Scene duck = load_scene(WHITTED_ASSETS_DIR "/gltf/Duck/glTF-Binary/Duck.glb", io);
    expect_wide_equals_binary(duck, OpaqueFilter{}, make_rays(duck, 2000, 78), "Duck");
}

/// Leaves of every size (1 to 3 packets, padded lanes), a root that is a leaf, nodes with fewer
/// children than lanes, and a degenerate tree (median splits of coincident centroids).
TEST(AccelWideBvh, OddShapedTrees) {
    OpaqueFilter filter;
    for (uint32_t n : {1u, 2u, 3u, 5u, 8u, 9u, 13u, 40u}) {
        Scene s;
        add_mesh_instance(s, make_soup(n, 3 + n, 1.f, 0.6f));
        const auto oracle = create_accelerator("brute", s, filter);
        for (const char* name : {"bvh", "bvh:width=4", "bvh:leaf=12,intersection_cost=0.01", "bvh:leaf=1"}) {
            const auto accel = create_accelerator(name, s, filter);
            size_t differ = 0;
            for (const Ray& r : make_rays(s, 300, n))
                differ += compare_hits(accel->intersect(r, RayKind::Camera), oracle->intersect(r, RayKind::Camera),
                                       kRelTol) == Agreement::Differ;
            EXPECT_EQ(differ, 0u) << name << " over " << n << " triangles";
        }
    }
    // Many different triangles with one centroid (the origin): no SAH plane exists, the builder
    // falls back to object-median splits.
    Scene s;
    Mesh m = make_soup(3000, 5, 1.f, 0.5f);
    for (uint32_t i = 0; i < 3000; ++i) {
        const float w = 1.f + 1e-3f * float(i), h = 0.25f + 1e-4f * float(i);
        m.positions.insert(m.positions.end(), {{-w, -h, 0.f}, {w, -h, 0.f}, {0.f, 2.f * h, 0.f}});
        const uint32_t b = uint32_t(m.positions.size()) - 3;
        m.indices.insert(m.indices.end(), {b, b + 1, b + 2});
    }
    add_mesh_instance(s, m);
    const auto oracle = create_accelerator("brute", s, filter);
    const auto accel = create_accelerator("bvh", s, filter);
    size_t differ = 0;
    for (const Ray& r : make_rays(s, 1000, 3))
        differ += compare_hits(accel->intersect(r, RayKind::Camera), oracle->intersect(r, RayKind::Camera), kRelTol) ==
                  Agreement::Differ;
    EXPECT_EQ(differ, 0u);
}

/// n instances laid out on a 7 x 7 x k lattice (neighbours' boxes overlap): small meshes of 2 to
/// 12 triangles (walls, panels) and a 96-triangle sphere. With `identity_only` every instance has
/// its own mesh placed by its vertices (identity transform, the case whose ray set-up the top
/// level shares); otherwise every other instance shares one of three meshes under a translation,
/// rotation and non-uniform (for some, mirroring) scale.
Scene many_instances_scene(uint32_t n, bool identity_only) {
    Scene s;
    auto at = [](uint32_t i) { return Vec3f(float(i % 7), float((i / 7) % 7), float(i / 49)) * 0.9f; };
    auto small_mesh = [](uint32_t i, Vec3f offset) {
        Mesh m = i % 5 == 4 ? make_uv_sphere({0, 0, 0}, 0.5f, 6, 8) : make_soup(2 + 5 * (i % 3), 11 + i, 0.5f, 0.6f);
        for (Vec3f& p : m.positions) p = p + offset;
        return m;
    };
    uint32_t shared = 0;
    if (!identity_only) {
        for (uint32_t k = 0; k < 3; ++k) s.meshes.push_back(small_mesh(k + 3, Vec3f(0.f)));
        shared = 3;
    }
    for (uint32_t i = 0; i < n; ++i) {
        if (identity_only || i % 2 == 0) {
            add_mesh_instance(s, small_mesh(i, at(i)));
            continue;
        }
        const Vec3f p = at(i);
        const double mirror = i % 4 == 1 ? -1.0 : 1.0;
        add_instance(s, i % shared,
                     Mat4d::translate({p.x, p.y, p.z}) * Mat4d::rotate(0.3 * double(i), 0.2, 0.9, 0.4) *
                         Mat4d::scale({mirror * 0.8, 1.1, 0.6 + 0.01 * double(i % 9)}));
    }
    return s;
}

/// Mesh BVHs that are 8-wide under either top level, for comparing the two top levels alone (a
/// scene without spheres: the sphere structure is never built).
struct NoSpheres {
    template <class Query>
    bool traverse(const Vec3f&, const Vec3f&, float, Query&) const { return false; }
    Bounds3f bounds() const { return {}; }
    BlasStats stats() const { return {}; }
};

template <class Top>
std::unique_ptr<Accelerator> wide_meshes_under(const Scene& s, const SurfaceFilter& filter,
                                               const std::function<Top(const std::vector<Bounds3f>&)>& top) {
    const BvhBuildConfig build = wide_bvh_build_defaults();
    return std::make_unique<TwoLevelAccelerator<float, WideTriangleBvh<8>, NoSpheres, Top>>(
        "bvh", s, filter, [build](const Mesh& m) { return WideTriangleBvh<8>(TrianglePrims<float>(m), build, {}); },
        [](AnalyticPrims<float>&&) {
            ADD_FAILURE() << "no spheres in these scenes";
            return NoSpheres{};
        },
        top);
}

/// The wide top level against the binary one over the same 8-wide mesh BVHs, bit for bit. The
/// wide top level tests each instance's box with slab_entry's rounding, so it culls exactly what
/// the binary one culled; only the order in which instances are visited differs, which can decide
/// between two instances' hits at exactly the same t (a tie, counted and printed). Returns the
/// ties.
size_t expect_top_levels_agree(const Scene& s, const SurfaceFilter& filter, const std::vector<Ray>& rays,
                               const std::string& label) {
    const auto wide = wide_meshes_under<WideInstanceTree<8>>(
        s, filter, [](const std::vector<Bounds3f>& b) { return WideInstanceTree<8>(b, WideBvhOptions{}); });
    const auto binary = wide_meshes_under<BinaryInstanceTree<float>>(
        s, filter, [](const std::vector<Bounds3f>& b) { return BinaryInstanceTree<float>(b, true); });
    EXPECT_LE(wide->stats().nodes, binary->stats().nodes);
    size_t ties = 0, bad = 0, bad_tr = 0;
    for (const Ray& ray : rays) {
        const Hit a = wide->intersect(ray, RayKind::Camera), b = binary->intersect(ray, RayKind::Camera);
        if (std::memcmp(&a, &b, sizeof a) != 0) {
            if (a.valid() && b.valid() && same_bits(a.t, b.t) && a.inst != b.inst)
                ++ties;
            else
                ++bad;
        }
        Ray seg = ray;
        seg.tfar = 1.f;
        const Color ta = wide->transmittance(seg), tb = binary->transmittance(seg);
        bad_tr += same_bits(ta.x, tb.x) && same_bits(ta.y, tb.y) && same_bits(ta.z, tb.z) ? 0 : 1;
    }
    std::printf("[ %s ] wide vs binary top level, %zu rays: %zu not bit-identical, %zu ties between instances, "
                "%zu transmittances differ\n",
                label.c_str(), rays.size(), bad, ties, bad_tr);
    EXPECT_EQ(bad, 0u) << label;
    EXPECT_EQ(bad_tr, 0u) << label;
    return ties;
}

/// The wide top level over instances (1, 2, 7, 8, 9: fewer than a node's lanes, a full node, one
/// more level; 64 and 300: several levels), identity and transformed instances: every `bvh` width
/// against brute force (hits, cut-outs, transparent shadows), and against the binary top level.
TEST(AccelWideBvh, WideTopLevelManyInstances) {
    PatternFilter filter;
    for (const bool identity_only : {true, false})
        for (const uint32_t n : {1u, 2u, 7u, 8u, 9u, 64u, 300u}) {
            const Scene s = many_instances_scene(n, identity_only);
            const std::string label = std::to_string(n) + (identity_only ? " identity" : " mixed") + " instances";
            SCOPED_TRACE(label);
            const std::vector<Ray> rays = make_rays(s, 300, 100 + n);
            const Reference ref(*create_accelerator("brute", s, filter), rays);
            for (const char* name : {"bvh", "bvh:width=4", "bvh:width=8,isa=sse2"}) {
                const auto accel = create_accelerator(name, s, filter);
                const CheckResult r = check_closest(*accel, ref);
                EXPECT_EQ(r.differ, 0u) << name;
                EXPECT_EQ(check_transmittance(*accel, ref, 1e-6f), 0u) << name;
            }
            expect_top_levels_agree(s, filter, ref.rays, label);
        }
}

/// The same comparison on the two bundled multi-instance scenes (walls of two triangles, the
/// room's corners where instances meet, translated and rotated instances), spheres left out (they
/// are traced beside the top level, the same for both).
TEST(AccelWideBvh, WideTopLevelOnBundledScenes) {
    ImportOptions io;
    io.load_textures = false;
    for (const char* file : {"/scenes/default.glb", "/scenes/glass_mirror_room.json"}) {
        Scene s = load_scene(std::string(WHITTED_ASSETS_DIR) + file, io);
        s.spheres.clear();
        ASSERT_GT(s.instances.size(), 2u) << file;
        expect_top_levels_agree(s, PatternFilter{}, make_rays(s, 4000, 91), file);
    }
}

TEST(AccelFactory, UnknownNamesAndOptionsAreOneLineErrors) {
    Scene s;
    OpaqueFilter f;
    try {
        (void)create_accelerator("kd-tree", s, f);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("available: embree, bvh, grid, octree, kdop, brute"), std::string::npos);
    }
    EXPECT_THROW((void)create_accelerator("bvh:precision=half", s, f), Error);
    EXPECT_THROW((void)create_accelerator("grid:lamda=4", s, f), Error);
    EXPECT_THROW((void)create_accelerator("bvh:bins", s, f), Error);
    EXPECT_NO_THROW((void)create_accelerator("bvh:precision=double,bv=sphere,bins=32,leaf=4", s, f));
    EXPECT_THROW((void)create_accelerator("bvh:width=3", s, f), Error);
    EXPECT_THROW((void)create_accelerator("bvh:precision=double,width=8", s, f), Error);
    EXPECT_THROW((void)create_accelerator("bvh:bv=sphere,width=4", s, f), Error);
    EXPECT_THROW((void)create_accelerator("bvh:isa=avx9", s, f), Error);
    EXPECT_NO_THROW((void)create_accelerator("bvh:precision=double,width=2", s, f));
    EXPECT_NO_THROW((void)create_accelerator("bvh:width=4,isa=sse2", s, f));
    EXPECT_NO_THROW((void)create_accelerator("bvh:width=8,isa=sse2,block=1", s, f));
}

}  // namespace
}  // namespace whitted
