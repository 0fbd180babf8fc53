// Every in-house backend against the brute-force oracle, hit for hit: random and edge-case rays
// over procedural meshes, instances and a real glTF asset; filter semantics (accept() cut-outs,
// transparent shadows with de-duplication); degenerate inputs.
//
// Tolerance: the in-house backends share the oracle's watertight triangle test and object-space
// transform, so the same primitive must come with the same t to 1e-6 relative. Where the closest
// primitive differs, the hit is accepted as a tie only if both t agree to 1e-6 relative (shared
// edges and vertices, where either triangle is a correct answer); ties are counted and printed.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>

#include "importers/scene_loader.h"
#include "renderer/core/error.h"
#include "tests/unit/test_accel_util.h"

namespace whitted {
namespace {

using namespace whitted::test;

constexpr float kRelTol = 1e-6f;

const std::vector<std::string>& fast_backends() {
    static const std::vector<std::string> names{"bvh", "bvh:bv=sphere", "kdop", "grid", "octree"};
    return names;
}

/// Other settings of the same backends, checked on the Duck only (to keep the suite fast).
const std::vector<std::string>& variant_backends() {
    static const std::vector<std::string> names{"bvh:bins=8,leaf=2", "grid:lambda=1", "octree:leaf=4,depth=6"};
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
        const Agreement a = compare_hits(accel.intersect(ref.rays[i], RayKind::Camera), ref.hits[i], kRelTol);
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
             bool variants = false) {
    const std::vector<Ray> rays = make_rays(scene, ray_count, 1234);
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

TEST(AccelDegenerate, HugeNextToTiny) {
    Scene s;
    Mesh m = make_soup(2000, 3, 1.f, 1e-4f);
    const uint32_t base = uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), {{-1e6f, -1e6f, 0.5f}, {1e6f, -1e6f, 0.5f}, {0, 1e6f, 0.5f}});
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
    add_mesh_instance(s, m);
    expect_sane(s, "huge+tiny");
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
}

}  // namespace
}  // namespace whitted
