// Production against the reference renderer (docs/integrator.md, "The reference renderer";
// ctest label `reference`). Each case renders a scene both ways at one ray per pixel centre with
// --min-weight 0 and --texture-filter none, then asserts:
//   - pixels whose ray trees agree (the same primitive at every closest hit, the same shadow rays
//     with the same outcome) agree within 1e-5 relative;
//   - PSNR over the whole image >= 60 dB;
// and prints every pixel beyond 1e-5 with its cause, classified from the two ray trees.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "importers/scene_loader.h"
#include "reference/reference_renderer.h"
#include "core/error.h"
#include "integrator/camera.h"
#include "integrator/render.h"
#include "scene/scene_builder.h"

namespace whitted {
namespace {

constexpr double kRelTol = 1e-5;
constexpr double kMinPsnr = 60.0;
/// Largest camera-ray barycentric difference accepted, in units of 2^-24 t / altitude.
constexpr double kCameraBaryUnits = 32.0;
/// A pixel's relative difference: its largest channel difference over its brightest channel,
/// max_c |production_c - reference_c| / max(max_c |production_c|, max_c |reference_c|, kFloor), so a
/// dark channel of a bright pixel is not judged against its own tiny value (vertex colours near 0
/// interpolated from bright ones carry the absolute rounding of the bright ones); a pixel darker
/// than kFloor compares its absolute difference to kRelTol * kFloor.
constexpr double kFloor = 1e-3;

// ---- Production's ray trees -----------------------------------------------------------------

struct ProdHit {
    uint32_t geom, inst, prim;
    float u, v;  ///< the accelerator's barycentrics
};

/// Wraps the renderer's accelerator and records, per pixel, the closest hits and shadow results of
/// the ray tree, in the order the integrator asks for them. The camera ray names the pixel (the
/// same bits as CameraModel::generate for the pixel centre). Single-threaded renders only.
class Recorder final : public Accelerator {
public:
    Recorder(const Accelerator& inner, const Camera& camera, int width, int height)
        : m_inner(inner) {
        trees.resize(size_t(width) * size_t(height));
        shadows.resize(trees.size());
        const CameraModel model(camera, width, height);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) m_pixel[key(model.generate(x + 0.5, y + 0.5))] = y * width + x;
    }
    Hit intersect(const Ray& ray, RayKind kind) const override {
        const Hit h = m_inner.intersect(ray, kind);
        if (kind == RayKind::Camera) {
            const auto it = m_pixel.find(key(ray));
            m_current = it == m_pixel.end() ? -1 : it->second;
        }
        if (m_current >= 0) trees[size_t(m_current)].push_back({h.geom, h.inst, h.prim, h.u, h.v});
        return h;
    }
    using Accelerator::intersect;
    using Accelerator::transmittance;
    Color transmittance(const Ray& ray) const override {
        const Color s = m_inner.transmittance(ray);
        if (m_current >= 0) shadows[size_t(m_current)].push_back(s);
        return s;
    }
    RayOffsetPolicy ray_offset() const override { return m_inner.ray_offset(); }
    std::string name() const override { return m_inner.name(); }
    AccelStats stats() const override { return m_inner.stats(); }

    mutable std::vector<std::vector<ProdHit>> trees;
    mutable std::vector<std::vector<Color>> shadows;

private:
    static std::string key(const Ray& r) {
        std::string k(sizeof(float) * 6, '\0');
        std::memcpy(k.data(), &r.org, sizeof(float) * 3);
        std::memcpy(k.data() + sizeof(float) * 3, &r.dir, sizeof(float) * 3);
        return k;
    }
    const Accelerator& m_inner;
    std::unordered_map<std::string, int> m_pixel;
    mutable int m_current = -1;
};

// ---- One comparison ---------------------------------------------------------------------------

struct Result {
    double psnr = 0.0;
    double max_rel = 0.0;             ///< over all pixels
    double max_rel_same_tree = 0.0;   ///< over the pixels whose trees agree
    double max_rel_unexplained = 0.0; ///< over those with no term that amplifies float rounding
    int unexplained = 0;              ///< pixels of those beyond kRelTol
    int same_tree_pixels = 0, pixels = 0;
    /// Camera rays hitting the same triangle both ways: the largest barycentric difference in units
    /// of 2^-24 t / altitude (what a float ray's rounding moves the hit by, over the triangle's size).
    double max_camera_bary = 0.0;
    std::map<std::string, int> causes;  ///< pixels beyond kRelTol, by cause
};

/// Why a pixel's two ray trees differ, from the first place they part.
std::string classify(const std::vector<ProdHit>& prod, const std::vector<ReferenceHitRecord>& ref,
                     const std::vector<Color>& prod_shadows, const std::vector<ReferenceShadowRecord>& ref_all, bool batch_differs,
                     std::string& detail) {
    if (batch_differs) return "exact tie (the camera-ray batch named another primitive)";
    const size_t n = std::min(prod.size(), ref.size());
    for (size_t k = 0; k < n; ++k) {
        const ReferenceHitRecord& r = ref[k];
        const ProdHit& p = prod[k];
        if (p.geom == r.geom && p.inst == r.inst && p.prim == r.prim) continue;
        detail = fmt::format("ray {} (depth {}): production geom {} prim {}, reference geom {} prim {} "
                             "(t {:.6g}, smallest barycentric {:.3g}, |cos| {:.3g})",
                             k, r.depth, int(p.geom), int(p.prim), int(r.geom), int(r.prim), r.t, r.edge, r.cos);
        const bool prod_miss = p.geom == kInvalidId, ref_miss = r.geom == kInvalidId;
        if (!ref_miss && r.edge < 1e-5) return "exact tie (a shared edge: the next triangle)";
        if (!ref_miss && r.edge < 1e-3) return "near an edge (float traversal crosses it elsewhere)";
        if (prod_miss != ref_miss && !ref_miss && r.cos < 0.05) return "grazing (silhouette)";
        if (prod_miss != ref_miss && !ref_miss && r.edge < 1e-2) return "near an edge (silhouette)";
        if (k > 0 && !ref_miss && r.t < 1e-4 * std::max(1.0, ref[k - 1].t))
            return "offset (secondary-ray origin: a surface within the offset)";
        if (!prod_miss && !ref_miss && std::fabs(r.t) > 0 && r.depth > 0)
            return "secondary ray: another primitive (offset or tie upstream)";
        return "another primitive";
    }
    if (prod.size() != ref.size()) {
        detail = fmt::format("tree sizes {} (production) vs {} (reference)", prod.size(), ref.size());
        return "tree shape (total internal reflection or depth decided differently)";
    }
    // Production casts no shadow ray for a highlight-only term below its cutoff (n (1 - N.H) >= 17).
    std::vector<Vec3d> ref_shadows;
    for (const ReferenceShadowRecord& r : ref_all)
        if (r.highlight_gap < 17.0) ref_shadows.push_back(r.s);
    if (prod_shadows.size() != ref_shadows.size()) {
        detail = fmt::format("{} shadow rays (production) vs {} (reference)", prod_shadows.size(), ref_shadows.size());
        return "shadow rays (cast on one side only)";
    }
    for (size_t k = 0; k < prod_shadows.size(); ++k) {
        const Vec3d p(prod_shadows[k]), r = ref_shadows[k];
        if (std::fabs(p.x - r.x) + std::fabs(p.y - r.y) + std::fabs(p.z - r.z) > 1e-3) {
            detail = fmt::format("shadow ray {}: s = {:.4g} (production) vs {:.4g} (reference)", k, p.x, r.x);
            return "shadow (an occluder's edge or the shadow-ray offset)";
        }
    }
    return "";
}

/// The largest difference of production's barycentrics from the reference's at one triangle hit
/// (u, v and the third one, 1 - u - v).
double barycentric_difference(const ProdHit& p, const ReferenceHitRecord& r) {
    return std::max({std::fabs(p.u - r.b1), std::fabs(p.v - r.b2), std::fabs(double(p.u) + p.v - r.b1 - r.b2)});
}

/// How far production's float barycentrics alone can move a pixel: at each triangle hit of the tree
/// the accelerator's (u, v) differ from the reference's by du (the float ray lands about 2^-24 t off,
/// a barycentric change of about 2^-24 t / altitude); the interpolated normal then moves by up to
/// du * spread (the vertex normals' largest difference), and the diffuse term kd N.L by that over
/// N.L, relative. The bound is the largest of du * spread / N.L over the tree's hits.
struct NormalBound {
    double bound = 0.0;
    std::string detail;
};
NormalBound normal_bound(const std::vector<ProdHit>& prod, const std::vector<ReferenceHitRecord>& ref) {
    NormalBound nb;
    for (size_t k = 0; k < ref.size() && k < prod.size(); ++k) {
        const ReferenceHitRecord& h = ref[k];
        if (h.geom == kInvalidId || h.normal_spread == 0.0) continue;
        const double du = barycentric_difference(prod[k], h);
        const double b = du * h.normal_spread / std::max(h.min_n_dot_l, 1e-3);
        if (b <= nb.bound) continue;
        nb.bound = b;
        nb.detail = fmt::format("ray {}: barycentrics {:.2g} apart ({:.1f} x 2^-24 t / altitude, t / altitude {:.3g}), "
                                "vertex normals {:.2g} apart, N.L {:.3g}: bound {:.2g}",
                                k, du, du / (0x1p-24 * h.t / h.altitude), h.t / h.altitude, h.normal_spread,
                                h.min_n_dot_l, b);
    }
    return nb;
}

/// Renders `scene` both ways and compares; prints every pixel beyond kRelTol with its cause.
Result compare(const std::string& name, const Scene& scene, RenderSettings rs, double ambient_bias = 0.0) {
    rs.aa.mode = AaMode::Center;
    rs.aa.texture_filter = TextureFilter::None;
    rs.integrator.min_weight = 0.f;
    rs.threads = 1;  // the recorder below is not thread-safe
    const Renderer renderer(scene, rs);
    const Film film = renderer.render();  // production: the specialised kernel, Embree packets
    const ImageSize size = renderer.image_size();
    Recorder recorder(renderer.accelerator(), scene.cameras[size_t(rs.camera)], size.width, size.height);
    IntegratorSettings general = rs.integrator;
    general.specialize = false;  // one query per ray, so every ray of a tree comes through the recorder
    const Film film_general = renderer.render(rs.aa, general, recorder);

    RenderSettings rs_ref = rs;
    rs_ref.integrator.ambient = rs.integrator.ambient + Color(float(ambient_bias));  // the control test's change
    const ReferenceImage ref = render_reference(scene, rs_ref, 2);
    EXPECT_EQ(ref.width, size.width);
    EXPECT_EQ(ref.height, size.height);

    Result res;
    double sum_sq = 0.0, peak = 1.0;
    res.pixels = size.width * size.height;
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            const size_t i = size_t(y) * size_t(size.width) + size_t(x);
            const Vec3d p(film.beauty[i]), r = ref.radiance[i];
            double diff = 0.0, magnitude = kFloor;
            for (int c = 0; c < 3; ++c) {
                const double d = p[c] - r[c];
                sum_sq += d * d;
                peak = std::max(peak, r[c]);
                diff = std::max(diff, std::fabs(d));
                magnitude = std::max({magnitude, std::fabs(p[c]), std::fabs(r[c])});
            }
            const double rel = diff / magnitude;
            res.max_rel = std::max(res.max_rel, rel);
            if (!recorder.trees[i].empty() && !ref.trees[i].empty()) {
                const ProdHit& q = recorder.trees[i][0];
                const ReferenceHitRecord& h = ref.trees[i][0];
                if (h.geom != kInvalidId && h.altitude > 0.0 && q.geom == h.geom && q.inst == h.inst && q.prim == h.prim) {
                    res.max_camera_bary =
                        std::max(res.max_camera_bary, barycentric_difference(q, h) / (0x1p-24 * h.t / h.altitude));
                }
            }
            const bool batch_differs = !(film.beauty[i] == film_general.beauty[i]);
            std::string detail;
            const std::string cause = classify(recorder.trees[i], ref.trees[i], recorder.shadows[i], ref.shadows[i],
                                               batch_differs, detail);
            if (cause.empty()) {
                ++res.same_tree_pixels;
                res.max_rel_same_tree = std::max(res.max_rel_same_tree, rel);
            }
            if (std::getenv("WHITTED_REFERENCE_DUMP") && x == std::atoi(std::getenv("WHITTED_REFERENCE_DUMP")) &&
                y == std::atoi(std::strchr(std::getenv("WHITTED_REFERENCE_DUMP"), ',') + 1)) {
                for (const ProdHit& h : recorder.trees[i]) std::printf("  prod hit %d %d %d\n", int(h.geom), int(h.inst), int(h.prim));
                for (const Color& c : recorder.shadows[i]) std::printf("  prod shadow %g %g %g\n", c.x, c.y, c.z);
                for (const ReferenceHitRecord& h : ref.trees[i])
                    std::printf("  ref hit %d %d %d t %g depth %d\n", int(h.geom), int(h.inst), int(h.prim), h.t, h.depth);
                for (const ReferenceShadowRecord& c : ref.shadows[i])
                    std::printf("  ref shadow %g %g %g gap %g\n", c.s.x, c.s.y, c.s.z, c.highlight_gap);
            }
            if (rel <= kRelTol) continue;
            std::string listed = cause;
            if (cause.empty()) {
                // The same primitives both ways: what amplifies production's float rounding here.
                double n = 0.0;
                bool textured = false, spot = false;
                int depth = 0;
                for (const ReferenceHitRecord& h : ref.trees[i]) {
                    n = std::max(n, h.highlight_n);
                    textured = textured || h.textured;
                    spot = spot || h.spot_ramp;
                    if (h.geom != kInvalidId) depth = std::max(depth, h.depth);
                }
                const NormalBound nb = normal_bound(recorder.trees[i], ref.trees[i]);
                if (n >= 10.0) listed = fmt::format("steep highlight (n up to {:.0f}: (N.H)^n scales float rounding by n)", n);
                else if (textured) listed = "texture lookup (float barycentrics move the UV between texels)";
                else if (spot) listed = "spot cone ramp (float cosine in the falloff)";
                else if (rel <= nb.bound) {
                    listed = "shading normal (float barycentrics, measured apart: the interpolated normal moves "
                             "with them)";
                    detail = nb.detail;
                } else if (depth >= 2)
                    listed = "deep ray tree (two or more bounces: float mirror and refraction directions compound)";
                else listed = "same ray tree, no amplifying term (unexplained)";
                if (listed.starts_with("same ray tree")) {
                    res.max_rel_unexplained = std::max(res.max_rel_unexplained, rel);
                    ++res.unexplained;
                }
            }
            ++res.causes[listed];
            std::printf("[%s] pixel (%d,%d) rel %.3g production (%.7g %.7g %.7g) reference (%.7g %.7g %.7g): %s%s%s\n",
                        name.c_str(), x, y, rel, p.x, p.y, p.z, r.x, r.y, r.z, listed.c_str(),
                        detail.empty() ? "" : ": ", detail.c_str());
        }
    const double mse = sum_sq / (3.0 * res.pixels);
    res.psnr = mse > 0.0 ? 10.0 * std::log10(peak * peak / mse) : 999.0;
    int listed = 0;
    for (const auto& [cause, count] : res.causes) listed += count;
    std::printf("[%s] %dx%d: PSNR %.1f dB, max rel %.3g (same-tree pixels %d/%d: max rel %.3g), %d pixel(s) beyond %.0e; "
                "camera-ray barycentrics within %.1f x 2^-24 t / altitude\n",
                name.c_str(), size.width, size.height, res.psnr, res.max_rel, res.same_tree_pixels, res.pixels,
                res.max_rel_same_tree, listed, kRelTol, res.max_camera_bary);
    for (const auto& [cause, count] : res.causes) std::printf("[%s]   %4d  %s\n", name.c_str(), count, cause.c_str());
    return res;
}

void expect_agreement(const Result& r) {
    EXPECT_GT(r.same_tree_pixels, r.pixels / 2) << "most pixels should have the same ray tree both ways";
    // Pixels with the same ray tree agree within kRelTol but where production's float rounding is
    // amplified by a term the reference names (listed with that cause), or where the float
    // barycentrics measured on the tree's hits bound the difference (normal_bound).
    EXPECT_EQ(r.unexplained, 0) << "same-tree pixels beyond " << kRelTol << " with no cause (largest "
                                << r.max_rel_unexplained << ")";
    EXPECT_GE(r.psnr, kMinPsnr);
    // The float barycentrics that normal_bound accepts are as close as a float ray allows (measured
    // at most 16.2 units, SimpleInstancing); a wrong interpolation (swapped u and v, say) is far off.
    EXPECT_LE(r.max_camera_bary, kCameraBaryUnits);
}

RenderSettings small(int width) {
    RenderSettings rs;
    rs.width = width;
    return rs;
}

// ---- Analytic scenes ---------------------------------------------------------------------------

WhittedCoeffs coeffs(Color kd, Color ks = Color(0.f), float n = 1.f, Color kr = Color(0.f), Color kt = Color(0.f),
                     float ior = 1.5f, bool thin = true) {
    WhittedCoeffs c;
    c.kd = c.ka = kd;
    c.ks = ks;
    c.n = n;
    c.kr = kr;
    c.kt = kt;
    c.ior = ior;
    c.thin = thin;
    return c;
}

/// A floor, a mirror box, a glass sphere and a thin tinted pane under a point light and a spot.
Scene analytic_scene() {
    Scene s;
    const uint32_t floor = add_classic_material(s, coeffs({0.6f, 0.55f, 0.5f}, Color(0.2f), 40.f));
    const uint32_t mirror = add_classic_material(s, coeffs(Color(0.05f), Color(0.5f), 200.f, Color(0.8f)));
    const uint32_t glass = add_classic_material(s, coeffs(Color(0.f), Color(0.1f), 500.f, Color(0.1f), Color(0.85f), 1.5f, false));
    const uint32_t pane = add_classic_material(s, coeffs(Color(0.05f), Color(0.f), 1.f, Color(0.f), {0.2f, 0.8f, 0.3f}));
    add_mesh(s, make_quad({-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, floor));
    add_mesh(s, make_box({-2.5f, 0, -2.5f}, {-1.f, 1.6f, -1.2f}, mirror));
    add_mesh(s, make_quad({0.8f, 0.f, -1.5f}, {2.4f, 0.f, -1.5f}, {2.4f, 1.8f, -1.5f}, {0.8f, 1.8f, -1.5f}, pane));
    Sphere sphere;
    sphere.center = {0.2, 0.9, 0.3};
    sphere.radius = 0.9;
    sphere.material = glass;
    s.spheres.push_back(sphere);
    s.lights.push_back(point_light({1.5, 4.0, 2.5}, 30.f));
    Light spot = point_light({-2.0, 3.5, 2.0}, 25.f, {1.f, 0.9f, 0.7f});
    spot.type = LightType::Spot;
    spot.direction = normalize(Vec3d(0.5, -1.0, -0.6));
    spot.inner_cone = 0.3f;
    spot.outer_cone = 0.6f;
    s.lights.push_back(spot);
    s.cameras.push_back(make_camera(CameraType::Perspective, {0.5, 2.5, 6.0}, normalize(Vec3d(-0.1, -0.35, -1.0)),
                                    {0, 1, 0}, 0.9));
    return s;
}

TEST(ReferenceCompare, AnalyticScene) { expect_agreement(compare("analytic", analytic_scene(), small(64))); }

TEST(ReferenceCompare, AnalyticSceneWithFresnelAndDepth2) {
    RenderSettings rs = small(48);
    rs.integrator.fresnel = true;
    rs.integrator.max_depth = 2;
    expect_agreement(compare("analytic-fresnel-depth2", analytic_scene(), rs));
}

TEST(ReferenceCompare, AnalyticOrthographicInfinitePlane) {
    Scene s;
    const uint32_t m = add_classic_material(s, coeffs({0.3f, 0.5f, 0.7f}, Color(0.3f), 20.f, Color(0.2f)));
    Plane p;
    p.point = {0, -1, 0};
    p.normal = {0, 1, 0};
    p.material = m;
    s.planes.push_back(p);
    Sphere sp;
    sp.center = {0, 0, 0};
    sp.radius = 1.0;
    sp.material = add_classic_material(s, coeffs({0.8f, 0.2f, 0.2f}, Color(0.5f), 60.f, Color(0.3f)));
    s.spheres.push_back(sp);
    Light sun;
    sun.type = LightType::Directional;
    sun.direction = normalize(Vec3d(-0.3, -1.0, -0.4));
    sun.attenuation = Attenuation::None;
    sun.intensity = 2.f;
    s.lights.push_back(sun);
    s.cameras.push_back(make_camera(CameraType::Orthographic, {0, 1.5, 5}, normalize(Vec3d(0, -0.3, -1)), {0, 1, 0}, 2.0));
    expect_agreement(compare("analytic-ortho-plane", s, small(48)));
}

// The comparison can fail: a change of 1e-3 in the ambient light on the reference side is caught.
TEST(ReferenceCompare, ControlAmbientChangeIsCaught) {
    const Result r = compare("control-ambient+1e-3", analytic_scene(), small(32), 1e-3);
    // expect_agreement's bound on unexplained pixels fails, by many pixels and far beyond kRelTol.
    EXPECT_GT(r.unexplained, r.pixels / 20);
    EXPECT_GT(r.max_rel_unexplained, 100 * kRelTol);
}

// ---- The bundled scene files ---------------------------------------------------------------------

Scene load(const std::string& relative) {
    ImportOptions io;
    io.no_environment = true;
    io.default_environment = false;  // glTF files without lights get the default light
    return load_scene(std::string(WHITTED_ASSETS_DIR) + "/" + relative, io);
}

/// A scene file's own settings, at a small width and with the reference's sampling.
RenderSettings scene_file_settings(const Scene& scene, int width) {
    RenderSettings rs;
    apply_scene_settings(scene.settings, rs);
    rs.width = width;
    rs.height = 0;
    return rs;
}

TEST(ReferenceCompare, SceneWhitted1980) {
    const Scene s = load("scenes/whitted1980.json");
    expect_agreement(compare("whitted1980.json", s, scene_file_settings(s, 64)));
}
TEST(ReferenceCompare, SceneGlassMirrorRoom) {
    const Scene s = load("scenes/glass_mirror_room.json");
    expect_agreement(compare("glass_mirror_room.json", s, scene_file_settings(s, 64)));
}
TEST(ReferenceCompare, SceneTransparentShadows) {
    const Scene s = load("scenes/transparent_shadows.json");
    expect_agreement(compare("transparent_shadows.json", s, scene_file_settings(s, 64)));
}
TEST(ReferenceCompare, SceneQuadrics) {
    // Cylinders, cones and discs: the reference intersects them its own way (each surface as a
    // plain quadratic or plane crossing, not the renderer's interval form).
    const Scene s = load("scenes/quadrics.json");
    ASSERT_GE(s.quadrics.size(), 8u);
    expect_agreement(compare("quadrics.json", s, scene_file_settings(s, 64)));
}
TEST(ReferenceCompare, SceneDefaultGlb) {
    const Scene s = load("scenes/default.glb");
    expect_agreement(compare("default.glb", s, small(64)));
}

// The shading-normal bound does not hide a real difference: on the smooth-normal spheres it
// explains, the same 1e-3 ambient change leaves most lit pixels unexplained.
TEST(ReferenceCompare, ControlAmbientChangeIsCaughtOnSmoothNormals) {
    const Scene s = load("gltf/MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb");
    const Result r = compare("control-spheres-ambient+1e-3", s, small(48), 1e-3);
    EXPECT_GT(r.unexplained, r.pixels / 20);
    EXPECT_GT(r.max_rel_unexplained, 100 * kRelTol);
}

// ---- glTF assets ----------------------------------------------------------------------------------

class ReferenceGltf : public ::testing::TestWithParam<const char*> {};

TEST_P(ReferenceGltf, AgreesWithProduction) {
    const std::string path = GetParam();
    const Scene s = load("gltf/" + path);
    expect_agreement(compare(path.substr(0, path.find('/')), s, small(48)));
}

INSTANTIATE_TEST_SUITE_P(
    Assets, ReferenceGltf,
    ::testing::Values("Box/glTF-Binary/Box.glb", "BoxTextured/glTF/BoxTextured.gltf",
                      "BoxVertexColors/glTF-Binary/BoxVertexColors.glb", "Duck/glTF-Binary/Duck.glb",
                      "AttenuationTest/glTF-Binary/AttenuationTest.glb",
                      "EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb",
                      "GlassHurricaneCandleHolder/glTF-Binary/GlassHurricaneCandleHolder.glb",
                      "LightsPunctualLamp/glTF/LightsPunctualLamp.gltf",
                      "MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb",
                      "NegativeScaleTest/glTF-Binary/NegativeScaleTest.glb",
                      "OrientationTest/glTF-Binary/OrientationTest.glb", "SpecularTest/glTF-Binary/SpecularTest.glb",
                      "TextureSettingsTest/glTF-Binary/TextureSettingsTest.glb",
                      "TextureTransformTest/glTF/TextureTransformTest.gltf", "UnlitTest/glTF-Binary/UnlitTest.glb",
                      "SimpleInstancing/glTF-Binary/SimpleInstancing.glb"),
    [](const ::testing::TestParamInfo<const char*>& info) {
        const std::string p = info.param;
        return p.substr(0, p.find('/'));
    });

// ---- What the reference refuses ------------------------------------------------------------------

TEST(ReferenceCompare, RefusesWhatItDoesNotModel) {
    const Scene s = analytic_scene();
    auto refused = [&](RenderSettings rs, const char* what) {
        rs.aa.texture_filter = TextureFilter::None;
        try {
            render_reference(s, rs);
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
            return;
        }
        ADD_FAILURE() << "not refused: " << what;
    };
    RenderSettings rs = small(8);
    rs.aa.mode = AaMode::Adaptive;
    refused(rs, "anti-aliasing");
    rs = small(8);
    rs.integrator.min_weight = 1.f / 255.f;
    refused(rs, "--min-weight");
    rs = small(8);
    rs.crop = PixelWindow{0, 0, 4, 4};
    refused(rs, "crop");
    rs = small(8);
    rs.camera = 3;
    refused(rs, "camera");
    RenderSettings mip = small(8);  // texture filter mip: set after the lambda's None
    EXPECT_THROW(render_reference(s, mip), Error);
    Scene env = s;
    env.environment.emplace();
    rs = small(8);
    rs.aa.texture_filter = TextureFilter::None;
    EXPECT_THROW(render_reference(env, rs), Error);
}

}  // namespace
}  // namespace whitted
