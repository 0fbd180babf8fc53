// The layered material extensions' formulas at cases with known answers (docs/materials.md,
// "Layers"): each layer switched off gives back the base, and each on does what its spec says.
#include <gtest/gtest.h>

#include <cmath>

#include "shading/layer_brdfs.h"
#include "shading/layered_model.h"
#include "shading/local_model.h"
#include "shading/optics.h"

namespace whitted {
namespace {

Material dielectric(Color base, float roughness) {
    Material m;
    m.base_color = {base.x, base.y, base.z, 1.f};
    m.metallic = 0.f;
    m.roughness = roughness;
    return m;
}

/// A frame with N = +z, the tangent frame on x and y, the viewer at `view_angle` from N in xz.
LayerFrame frame_at(float view_angle) {
    LayerFrame f;
    f.N = f.Nc = {0, 0, 1};
    f.T = {1, 0, 0};
    f.B = {0, 1, 0};
    f.V = {std::sin(view_angle), 0.f, std::cos(view_angle)};
    return f;
}

void expect_same(const WhittedCoeffs& a, const WhittedCoeffs& b) {
    EXPECT_EQ(a.kd, b.kd);
    EXPECT_EQ(a.ka, b.ka);
    EXPECT_EQ(a.ks, b.ks);
    EXPECT_EQ(a.n, b.n);
    EXPECT_EQ(a.kr, b.kr);
    EXPECT_EQ(a.kg, b.kg);
    EXPECT_EQ(a.kt, b.kt);
    EXPECT_EQ(a.emission, b.emission);
    EXPECT_EQ(a.roughness, b.roughness);
}

void expect_near(const Color& a, const Color& b, float tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

/// Light directions over the upper hemisphere and a few below it.
std::vector<Vec3f> light_directions() {
    std::vector<Vec3f> ls;
    for (int i = 0; i < 7; ++i)
        for (int j = 0; j < 8; ++j) {
            const float theta = -1.4f + 2.8f * float(i) / 6.f, phi = 0.8f * float(j);
            ls.push_back(normalize(Vec3f{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)}));
        }
    return ls;
}

/// Every layer at its "off" value must give the base: the same coefficients and the same light
/// term as the ordinary mapping and local model, bit for bit.
void expect_layer_off_is_base(const Material& m, const PbrSample& sample) {
    const MappingOptions options;
    for (float angle : {0.f, 0.7f, 1.4f}) {
        const LayerFrame f = frame_at(angle);
        LayerCoeffs l;
        const WhittedCoeffs c = map_layered(m, sample, f, options, l);
        const WhittedCoeffs base = map_gltf_material(m, sample, options);
        expect_same(c, base);
        EXPECT_EQ(l.coat, 0.f);
        EXPECT_TRUE(is_black(l.sheen));
        EXPECT_TRUE(is_black(l.kdt));
        for (const Vec3f& L : light_directions()) {
            const float n_dot_l = dot(f.N, L);
            if (n_dot_l <= 0.f) {
                EXPECT_EQ(layered_term(c, l, f.N, L, f.V, n_dot_l, false), Color(0.f));
                continue;
            }
            EXPECT_EQ(layered_term(c, l, f.N, L, f.V, n_dot_l, false), local_term(base, f.N, L, f.V, n_dot_l));
        }
    }
}

TEST(LayeredModel, EachLayerAtItsOffValueIsTheBase) {
    const Material m = dielectric({0.6f, 0.3f, 0.2f}, 0.4f);
    PbrSample s = constant_pbr_sample(m);
    expect_layer_off_is_base(m, s);  // everything off
    PbrSample coat = s;
    coat.clearcoat = 0.f;  // coat factor 0
    coat.clearcoat_roughness = 0.5f;
    expect_layer_off_is_base(m, coat);
    PbrSample sheen = s;
    sheen.sheen_color = Color(0.f);  // sheen colour 0
    sheen.sheen_roughness = 0.7f;
    expect_layer_off_is_base(m, sheen);
    PbrSample film = s;
    film.iridescence = 0.f;  // iridescence factor 0
    film.iridescence_thickness = 400.f;
    expect_layer_off_is_base(m, film);
    PbrSample aniso = s;
    aniso.anisotropy = 0.f;  // strength 0
    aniso.anisotropy_direction = {0.f, 1.f};
    expect_layer_off_is_base(m, aniso);
}

TEST(LayeredModel, ClearcoatWeighsTheBaseByItsFresnel) {
    const Material m = dielectric({0.8f, 0.1f, 0.1f}, 0.6f);
    PbrSample s = constant_pbr_sample(m);
    s.clearcoat = 1.f;
    s.clearcoat_roughness = 0.f;
    const MappingOptions options;
    const WhittedCoeffs base = map_gltf_material(m, s, options);
    for (float angle : {0.f, 0.8f, 1.3f}) {
        const LayerFrame f = frame_at(angle);
        LayerCoeffs l;
        const WhittedCoeffs c = map_layered(m, s, f, options, l);
        // w = 0.04 + 0.96 (1 - N.V)^5 (KHR_materials_clearcoat), 0.04 at normal incidence.
        const float x = 1.f - std::cos(angle);
        const float w = 0.04f + 0.96f * x * x * x * x * x;
        EXPECT_NEAR(l.coat, w, 1e-6f);
        expect_near(c.kd, base.kd * (1.f - w), 1e-6f);
        expect_near(c.ks, base.ks * (1.f - w), 1e-6f);
        // A smooth coat is a mirror: all its weight on the mirror ray.
        EXPECT_NEAR(l.coat_kr, w, 1e-6f);
        EXPECT_EQ(l.coat_kg, 0.f);
    }
    // Its highlight: w at the mirror direction about the coat normal.
    const LayerFrame f = frame_at(0.5f);
    LayerCoeffs l;
    const WhittedCoeffs c = map_layered(m, s, f, options, l);
    const Vec3f L = reflect(f.V, f.N);
    const Color with = layered_term(c, l, f.N, L, f.V, dot(f.N, L), false);
    const Color below = local_term(c, f.N, L, f.V, dot(f.N, L));
    expect_near(with - below, Color(l.coat), 1e-5f);
    // Half the coat factor, half the weight.
    s.clearcoat = 0.5f;
    LayerCoeffs half;
    map_layered(m, s, f, options, half);
    EXPECT_NEAR(half.coat, 0.5f * l.coat, 1e-6f);
}

TEST(LayeredModel, ClearcoatDarkensEmission) {
    Material m = dielectric({0.5f, 0.5f, 0.5f}, 0.5f);
    m.emissive = Color(1.f);
    PbrSample s = constant_pbr_sample(m);
    s.clearcoat = 1.f;
    LayerCoeffs l;
    const WhittedCoeffs c = map_layered(m, s, frame_at(0.f), {}, l);
    expect_near(c.emission, Color(1.f - l.coat), 1e-6f);
}

TEST(LayeredModel, SheenScalesTheBaseByItsAlbedo) {
    const Material m = dielectric({0.2f, 0.2f, 0.6f}, 0.8f);
    PbrSample s = constant_pbr_sample(m);
    s.sheen_color = {1.f, 0.5f, 0.25f};
    s.sheen_roughness = 0.5f;
    const MappingOptions options;
    const WhittedCoeffs base = map_gltf_material(m, s, options);
    const LayerFrame f = frame_at(1.0f);
    LayerCoeffs l;
    const WhittedCoeffs c = map_layered(m, s, f, options, l);
    const float e = sheen_albedo(std::cos(1.0f), 0.5f);
    ASSERT_GT(e, 0.f);
    EXPECT_NEAR(l.base_v, 1.f - 1.f * e, 1e-6f);  // max3(sheenColor) = 1
    expect_near(c.kd, base.kd * (1.f - e), 1e-6f);
    expect_near(l.sheen_ambient, s.sheen_color * e, 1e-6f);
    // The light term: pi sheenColor D V N.L on top of the scaled base.
    const Vec3f L = normalize(Vec3f{-0.6f, 0.2f, 0.5f});
    const float n_dot_l = dot(f.N, L);
    const Vec3f H = normalize(L + f.V);
    const float base_l = 1.f - sheen_albedo(n_dot_l, 0.5f);
    const Color want = local_term(c, f.N, L, f.V, n_dot_l) * std::min(1.f, base_l / l.base_v) +
                       s.sheen_color * (kPi * charlie_distribution(dot(f.N, H), 0.25f) *
                                        charlie_visibility(n_dot_l, std::cos(1.0f), 0.25f) * n_dot_l);
    expect_near(layered_term(c, l, f.N, L, f.V, n_dot_l, false), want, 1e-5f);
}

TEST(LayeredModel, ThinFilmOfZeroThicknessIsTheBaseFresnelAtTheView) {
    const Material m = dielectric({0.5f, 0.5f, 0.5f}, 0.0f);
    PbrSample s = constant_pbr_sample(m);
    s.iridescence = 1.f;
    s.iridescence_thickness = 0.f;
    const WhittedCoeffs base = map_gltf_material(m, s, {});
    for (float angle : {0.f, 0.6f, 1.2f}) {
        LayerCoeffs l;
        const WhittedCoeffs c = map_layered(m, s, frame_at(angle), {}, l);
        // F = Schlick(F0, N.V) of the same dielectric.
        expect_near(c.ks, schlick(base.ks, std::cos(angle)), 1e-4f);
    }
    // A film of 400 nm colours the reflection.
    s.iridescence_thickness = 400.f;
    LayerCoeffs l;
    const WhittedCoeffs c = map_layered(m, s, frame_at(0.f), {}, l);
    EXPECT_GT(max_component(c.ks) - std::min({c.ks.x, c.ks.y, c.ks.z}), 0.01f);
}

TEST(LayeredModel, AnisotropyStretchesTheHighlightAlongItsDirection) {
    const Material m = dielectric({0.1f, 0.1f, 0.1f}, 0.2f);
    PbrSample s = constant_pbr_sample(m);
    s.anisotropy = 0.8f;
    s.anisotropy_direction = {1.f, 0.f};  // along T = +x
    const LayerFrame f = frame_at(0.f);
    LayerCoeffs l;
    const WhittedCoeffs c = map_layered(m, s, f, {}, l);
    ASSERT_TRUE(l.anisotropic);
    EXPECT_LT(l.n_t, l.n_b);
    // Half vectors tilted by the same angle along T and along B: the lobe is wider along T.
    auto highlight = [&](Vec3f L) { return layered_term(c, l, f.N, L, f.V, dot(f.N, L), false) - c.kd * dot(f.N, L); };
    const Vec3f along_t = normalize(Vec3f{0.3f, 0.f, 1.f}), along_b = normalize(Vec3f{0.f, 0.3f, 1.f});
    EXPECT_GT(highlight(along_t).x, 10.f * highlight(along_b).x);
    // The rotated direction swaps them.
    s.anisotropy_direction = {0.f, 1.f};
    LayerCoeffs r;
    const WhittedCoeffs cr = map_layered(m, s, f, {}, r);
    auto rotated = [&](Vec3f L) { return layered_term(cr, r, f.N, L, f.V, dot(f.N, L), false) - cr.kd * dot(f.N, L); };
    EXPECT_NEAR(rotated(along_b).x, highlight(along_t).x, 1e-4f);
    // A surface that is rough along T keeps no mirror ray there.
    EXPECT_LT(max_component(c.kr), max_component(map_gltf_material(m, s, {}).kr));
}

TEST(LayeredModel, DiffuseTransmissionMovesTheDiffuseLobeBehind) {
    const Material m = dielectric({0.6f, 0.6f, 0.6f}, 1.f);
    PbrSample s = constant_pbr_sample(m);
    const WhittedCoeffs opaque = map_gltf_material(m, s, {});
    s.diffuse_transmission = 1.f;
    s.diffuse_transmission_color = {1.f, 0.5f, 0.f};
    const LayerFrame f = frame_at(0.f);
    LayerCoeffs l;
    const WhittedCoeffs c = map_layered(m, s, f, {}, l);
    EXPECT_EQ(c.kd, Color(0.f));
    // The lobe's weight without the base colour, tinted by the transmission colour.
    expect_near(l.kdt, Color(1.f, 0.5f, 0.f) * (opaque.kd.x / 0.6f), 1e-6f);
    const Vec3f behind = normalize(Vec3f{0.2f, 0.f, -1.f});
    expect_near(layered_term(c, l, f.N, behind, f.V, dot(f.N, behind), false), l.kdt * -dot(f.N, behind), 1e-6f);
    // Half of it: half each way.
    s.diffuse_transmission = 0.5f;
    LayerCoeffs h;
    const WhittedCoeffs ch = map_layered(m, s, f, {}, h);
    expect_near(ch.kd, opaque.kd * 0.5f, 1e-6f);
    expect_near(h.kdt, l.kdt * 0.5f, 1e-6f);
}

TEST(LayeredModel, DispersionFollowsTheAbbeNumber) {
    // KHR_materials_dispersion: dispersion = 20 / V_d, V_d = (n_d - 1) / (n_F - n_C); the spec's
    // sample spreads n_F - n_C = (n_d - 1) 0.05 dispersion around n_d.
    for (float ior : {1.33f, 1.5f, 2.42f})
        for (float dispersion : {0.1f, 1.f, 3.f}) {
            const Color iors = dispersion_iors(ior, dispersion);
            EXPECT_EQ(iors.y, ior);
            EXPECT_NEAR((ior - 1.f) / (iors.z - iors.x), 20.f / dispersion, 1e-2f * 20.f / dispersion);
            EXPECT_LT(iors.x, iors.z);  // blue bends more than red
        }
    EXPECT_EQ(dispersion_iors(1.5f, 0.f), Color(1.5f));
    // The spec's worked numbers: ior 1.5, dispersion 1 -> half spread 0.0125.
    expect_near(dispersion_iors(1.5f, 1.f), {1.4875f, 1.5f, 1.5125f}, 1e-6f);
}

TEST(LayeredModel, SpecularGlossinessLimits) {
    Material m;
    m.specular_glossiness = true;
    m.base_color = {0.7f, 0.5f, 0.3f, 1.f};  // diffuseFactor
    m.metallic = 0.f;
    // White specular: F0 = 1, no diffuse light left.
    m.sg_specular = Color(1.f);
    m.glossiness = 1.f;
    m.roughness = 0.f;
    WhittedCoeffs c = map_material_constant(m, {});
    EXPECT_EQ(c.ks, Color(1.f));
    EXPECT_EQ(c.kd, Color(0.f));
    EXPECT_EQ(c.kr, Color(1.f));  // glossiness 1: a mirror
    // Black specular: no reflection, the diffuse colour as is.
    m.sg_specular = Color(0.f);
    c = map_material_constant(m, {});
    EXPECT_EQ(c.ks, Color(0.f));
    expect_near(c.kd, {0.7f, 0.5f, 0.3f}, 1e-6f);
    // c_diff = diffuse (1 - max(specular)), F0 = specular, roughness = 1 - glossiness.
    m.sg_specular = {0.2f, 0.1f, 0.05f};
    m.glossiness = 0.25f;
    m.roughness = 0.75f;
    c = map_material_constant(m, {});
    expect_near(c.ks, {0.2f, 0.1f, 0.05f}, 1e-6f);
    expect_near(c.kd, Color(0.7f, 0.5f, 0.3f) * 0.8f, 1e-6f);
    EXPECT_FLOAT_EQ(c.roughness, 0.75f);
}

TEST(LayeredModel, NoNaNAtDegenerateInputs) {
    Material m = dielectric({1.f, 1.f, 1.f}, 0.f);
    PbrSample s = constant_pbr_sample(m);
    s.clearcoat = 1.f;
    s.sheen_color = Color(1.f);
    s.sheen_roughness = 0.f;
    s.iridescence = 1.f;
    s.iridescence_thickness = 1e9f;
    s.anisotropy = 1.f;
    s.diffuse_transmission = 1.f;
    for (float angle : {0.f, 1.5707f, 1.5708f}) {
        LayerCoeffs l;
        const LayerFrame f = frame_at(angle);
        const WhittedCoeffs c = map_layered(m, s, f, {}, l);
        EXPECT_TRUE(is_finite(c.kd) && is_finite(c.ks) && is_finite(c.kr) && is_finite(c.kg));
        for (const Vec3f& L : light_directions()) {
            const Color t = layered_term(c, l, f.N, L, f.V, dot(f.N, L), true);
            EXPECT_TRUE(is_finite(t)) << angle;
        }
    }
}

}  // namespace
}  // namespace whitted
