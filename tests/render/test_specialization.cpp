// Scene-aware specialisation (docs/performance.md): the kernel the scene analysis selects must give
// the same image as the general kernel, bit for bit, whenever min_weight is 0 (it only skips work
// that contributes exactly zero); light culling must never change the image; the analysis flags
// must describe the scenes correctly. Correctness only: no timings here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

#include "accel/factory/create_accelerator.h"
#include "importers/scene_loader.h"
#include "integrator/render.h"
#include "scene/scene_builder.h"
#include "shading/environment_map.h"
#include "shading/scene_analysis.h"

namespace whitted {
namespace {

const std::string kAssets = WHITTED_ASSETS_DIR;

/// Pixel-by-pixel float equality (-0 == +0; no NaN reaches the film).
::testing::AssertionResult same_image(const Film& a, const Film& b) {
    if (a.beauty.size() != b.beauty.size()) return ::testing::AssertionFailure() << "sizes differ";
    size_t differing = 0, first = 0;
    for (size_t i = 0; i < a.beauty.size(); ++i)
        if (!(a.beauty[i] == b.beauty[i]) && differing++ == 0) first = i;
    if (differing == 0) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << differing << " pixels differ, first at index " << first << ": ("
                                         << a.beauty[first].x << ", " << a.beauty[first].y << ", " << a.beauty[first].z
                                         << ") vs (" << b.beauty[first].x << ", " << b.beauty[first].y << ", "
                                         << b.beauty[first].z << ")";
}

void expect_same_rays(const RayCounters& a, const RayCounters& b) {
    EXPECT_EQ(a.camera, b.camera);
    EXPECT_EQ(a.shadow, b.shadow);
    EXPECT_EQ(a.reflection, b.reflection);
    EXPECT_EQ(a.refraction, b.refraction);
    EXPECT_EQ(a.shadow_skipped_unreached, b.shadow_skipped_unreached);
    EXPECT_EQ(a.shadow_skipped_facing, b.shadow_skipped_facing);
    EXPECT_EQ(a.shadow_skipped_zero, b.shadow_skipped_zero);
    EXPECT_TRUE(a == b) << "another counter differs (secondary_skipped_cutoff, aov_probe, contact_probe)";
}

RenderSettings small_settings(const Scene& scene, int width) {
    RenderSettings rs;
    apply_scene_settings(scene.settings, rs);
    rs.width = width;
    rs.height = 0;
    rs.aa = AaSettings{};  // center
    rs.integrator.min_weight = 0.f;
    return rs;
}

/// Renders `scene` with the general and the specialised kernel on one accelerator (centre samples
/// and adaptive anti-aliasing, plain and Fresnel-weighted) and expects identical images and rays.
/// The specialised kernels send camera rays as batches (Embree packets), the general one ray by
/// ray; Embree's camera-ray queries break exact ties in t by the same rule on both paths
/// (camera_tie_filter, issue 25), so the default accelerator (packets of 4) must give the same
/// image as single-ray queries (`packet=1`). Returns the specialised kernel.
KernelFeatures expect_specialised_equals_general(const Scene& scene, int width) {
    const RenderSettings rs = small_settings(scene, width);
    const Renderer renderer(scene, rs);
    const auto single = create_accelerator("embree:packet=1", scene, renderer.view(), AccelConfig{rs.robust});
    AaSettings adaptive;
    adaptive.mode = AaMode::Adaptive;
    for (const Accelerator* accel : {static_cast<const Accelerator*>(single.get()), &renderer.accelerator()}) {
        for (const AaSettings& aa : {AaSettings{}, adaptive}) {
            for (const bool fresnel : {false, true}) {
                if (fresnel && accel != single.get()) continue;  // packets: the plain weights suffice (test time)
                SCOPED_TRACE(std::string(aa_mode_name(aa.mode)) + (fresnel ? ", fresnel" : "") +
                             (accel == single.get() ? ", single rays" : ", packets"));
                IntegratorSettings general = rs.integrator;
                general.specialize = false;
                general.fresnel = fresnel;
                IntegratorSettings special = general;
                special.specialize = true;
                RenderStats sg, ss;
                const Film fg = renderer.render(aa, general, *accel, &sg);
                const Film fs = renderer.render(aa, special, *accel, &ss);
                EXPECT_TRUE(same_image(fg, fs));
                expect_same_rays(sg.rays, ss.rays);
                EXPECT_GT(ss.rays.camera, 0u);
            }
        }
    }
    return renderer.kernel();
}

// Issue 25 requirement 3: the case that showed it. TransmissionTest at 800 px, adaptive: one
// corner sample between pixels (422..423, 106..107) met two primitives at the same t, and Embree's
// packet traversal (the specialised kernel) and its single-ray traversal (the general one) kept
// different ones: 4 pixels differed by one half-float ulp. The crop around them, both kernels on
// the default accelerator.
TEST(Specialization, PacketsAndSingleRaysBreakTransmissionTestsTieAlike) {
    const Scene scene = load_scene(kAssets + "/gltf/TransmissionTest/glTF-Binary/TransmissionTest.glb");
    RenderSettings rs;
    rs.width = 800;
    rs.crop = PixelWindow{400, 90, 448, 122};
    rs.aa.mode = AaMode::Adaptive;
    rs.integrator.min_weight = 0.f;
    const Renderer renderer(scene, rs);
    IntegratorSettings general = rs.integrator;
    general.specialize = false;
    IntegratorSettings special = general;
    special.specialize = true;
    const Film fg = renderer.render(rs.aa, general, renderer.accelerator());
    const Film fs = renderer.render(rs.aa, special, renderer.accelerator());
    EXPECT_TRUE(same_image(fg, fs));
}

// ---- every bundled scene, and glTF assets with textures, alpha blend, transmission, volumes ----

class SpecialisedEqualsGeneral : public ::testing::TestWithParam<std::string> {};

TEST_P(SpecialisedEqualsGeneral, BitIdenticalAtMinWeightZero) {
    const Scene scene = load_scene(kAssets + "/" + GetParam());
    const KernelFeatures k = expect_specialised_equals_general(scene, 48);
    EXPECT_TRUE(k.tables);  // the specialised kernel was really used
}

INSTANTIATE_TEST_SUITE_P(
    Assets, SpecialisedEqualsGeneral,
    ::testing::Values("scenes/whitted1980.json", "scenes/transparent_shadows.json", "scenes/glass_mirror_room.json",
                      "scenes/default.glb", "gltf/Duck/glTF-Binary/Duck.glb",
                      "gltf/MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb",
                      "gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf",
                      "gltf/AttenuationTest/glTF-Binary/AttenuationTest.glb",
                      "gltf/GlassHurricaneCandleHolder/glTF-Binary/GlassHurricaneCandleHolder.glb",
                      "gltf/BoxVertexColors/glTF-Binary/BoxVertexColors.glb", "gltf/UnlitTest/glTF-Binary/UnlitTest.glb",
                      "gltf/EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb",
                      "gltf/TextureSettingsTest/glTF-Binary/TextureSettingsTest.glb",
                      "gltf/NegativeScaleTest/glTF-Binary/NegativeScaleTest.glb",
                      "gltf/ClearCoatTest/glTF-Binary/ClearCoatTest.glb",
                      "gltf/AnisotropyRotationTest/glTF-Binary/AnisotropyRotationTest.glb"),
    [](const ::testing::TestParamInfo<std::string>& info) {
        std::string name = info.param.substr(info.param.rfind('/') + 1);
        name = name.substr(0, name.find('.'));
        for (char& c : name)
            if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
        return name;
    });

// ---- synthetic glTF scenes: alpha MASK (opaque kernel), BLEND, vertex colors, unused glass ----

/// A 2x2 RGBA texture whose alpha alternates 0 / 255 (a cut-out checker).
uint32_t add_mask_texture(Scene& s) {
    Texture t;
    t.name = "mask";
    t.levels.resize(1);
    t.levels[0].width = t.levels[0].height = 2;
    t.levels[0].texels = {255, 255, 255, 255, 255, 255, 255, 0, 255, 255, 255, 0, 255, 255, 255, 255};
    t.use_mips = false;
    t.mag_filter = t.min_filter = FilterMode::Nearest;
    s.textures.push_back(t);
    return uint32_t(s.textures.size() - 1);
}

uint32_t add_gltf_material(Scene& s, const Material& m) {
    s.materials.push_back(m);
    return uint32_t(s.materials.size() - 1);
}

Mesh with_uvs(Mesh m, float scale) {
    m.uv0.clear();
    for (const Vec3f& p : m.positions) m.uv0.push_back({p.x * scale, p.y * scale});
    return m;
}

/// Floor, a cut-out (MASK) panel in front of a light, and optionally a BLEND panel and a glass
/// material nothing uses.
Scene gltf_panels(bool blend, bool unused_glass) {
    Scene s;
    Material floor;
    floor.metallic = 0.f;
    floor.roughness = 0.6f;
    floor.base_color = {0.7f, 0.65f, 0.6f, 1.f};
    add_mesh(s, make_quad({-6, -6, 0}, {6, -6, 0}, {6, 6, 0}, {-6, 6, 0}, add_gltf_material(s, floor)));
    Material mask;
    mask.metallic = 0.f;
    mask.roughness = 0.9f;
    mask.alpha_mode = AlphaMode::Mask;
    mask.base_color_texture.texture = int32_t(add_mask_texture(s));
    mask.double_sided = true;
    add_mesh(s, with_uvs(make_quad({-2, -1, 0.5f}, {2, -1, 0.5f}, {2, -1, 3}, {-2, -1, 3}, add_gltf_material(s, mask)), 2.f));
    if (blend) {
        Material b;
        b.metallic = 0.f;
        b.roughness = 0.1f;
        b.alpha_mode = AlphaMode::Blend;
        b.base_color = {0.2f, 0.4f, 0.9f, 0.45f};
        add_mesh(s, make_quad({0.5f, 1, 0.2f}, {3, 1, 0.2f}, {3, 1, 2.5f}, {0.5f, 1, 2.5f}, add_gltf_material(s, b)));
    }
    if (unused_glass) {
        Material g;
        g.metallic = 0.f;
        g.roughness = 0.f;
        g.transmission = 1.f;
        add_gltf_material(s, g);
    }
    s.lights.push_back(point_light({0.5, -4, 5}, 40.f));
    s.lights.push_back(point_light({-3, 3, 4}, 20.f, {0.7f, 0.8f, 1.f}));
    s.cameras.push_back(make_camera(CameraType::Perspective, {0, -9, 4}, {0, 9, -3.5}, {0, 0, 1}, 0.8));
    return s;
}

TEST(Specialization, AlphaMaskSceneUsesTheOpaqueKernelAndMatchesTheGeneralOne) {
    const Scene s = gltf_panels(false, true);
    const SceneAnalysis a = analyze_scene(s);
    EXPECT_TRUE(a.features.alpha_mask);
    EXPECT_TRUE(a.features.opaque());  // a cut-out passes all or nothing: no transmittance products
    EXPECT_FALSE(a.materials.back().used);
    EXPECT_TRUE(a.materials.back().transmission);  // the unused glass...
    EXPECT_FALSE(a.features.transmission);         // ...does not make the scene transmissive
    const KernelFeatures k = expect_specialised_equals_general(s, 64);
    EXPECT_FALSE(k.transmission);
    EXPECT_TRUE(k.attributes);  // the mask is a texture
}

TEST(Specialization, AlphaBlendSceneMatchesTheGeneralOne) {
    const Scene s = gltf_panels(true, false);
    EXPECT_TRUE(analyze_scene(s).features.alpha_blend);
    const KernelFeatures k = expect_specialised_equals_general(s, 64);
    EXPECT_TRUE(k.transmission);
}

TEST(Specialization, VertexColorsMakeAMaterialVarying) {
    Scene s = gltf_panels(false, false);
    s.meshes[0].colors.assign(s.meshes[0].positions.size(), Vec4f{0.9f, 0.2f, 0.1f, 1.f});
    s.meshes[0].colors[2] = Vec4f{0.1f, 0.9f, 0.3f, 1.f};
    const SceneAnalysis a = analyze_scene(s);
    EXPECT_TRUE(a.materials[0].vertex_colors);
    EXPECT_TRUE(a.materials[0].varying);
    expect_specialised_equals_general(s, 64);
}

// ---- light culling: range-limited and spot lights over separate objects ----

/// A row of floor tiles (one mesh and instance each) under range-limited point lights and spot
/// lights, some reaching only part of the row; a sphere and an infinite plane too.
Scene culling_scene() {
    Scene s;
    WhittedCoeffs c;
    c.kd = c.ka = Color(0.6f);
    c.ks = Color(0.2f);
    c.n = 30.f;
    const uint32_t m = add_classic_material(s, c);
    for (int i = 0; i < 8; ++i) {
        const float x0 = -8.f + 2.f * float(i);
        add_mesh(s, make_quad({x0, -2, 0}, {x0 + 1.9f, -2, 0}, {x0 + 1.9f, 2, 0}, {x0, 2, 0}, m));
    }
    Sphere sp;
    sp.center = {6.5, 4, 1};
    sp.radius = 1;
    sp.material = m;
    s.spheres.push_back(sp);
    Plane wall;
    wall.point = {0, 6, 0};
    wall.normal = {0, -1, 0};
    wall.u_axis = {1, 0, 0};
    wall.material = m;
    s.planes.push_back(wall);
    // glTF-style point lights with a range: each reaches a few tiles.
    for (double x : {-6.0, 1.0}) {
        Light l = point_light({x, 0, 1.5}, 8.f);
        l.range = 3.2f;
        s.lights.push_back(l);
    }
    // A range that ends just past the nearest point of the tile at x in [2, 3.9] (1.58114 away):
    // that tile is barely lit and must keep the light.
    Light edge = point_light({0.5, 0, 0.5}, 5.f);
    edge.range = 1.5812f;
    s.lights.push_back(edge);
    // Spot lights: narrow cones onto single tiles.
    for (double x : {-3.0, 5.0}) {
        Light l;
        l.type = LightType::Spot;
        l.position = {x, 0, 3};
        l.direction = {0, 0, -1};
        l.intensity = 30.f;
        l.inner_cone = 0.1f;
        l.outer_cone = 0.25f;
        s.lights.push_back(l);
    }
    // A spot pointing away from everything.
    Light away;
    away.type = LightType::Spot;
    away.position = {0, 0, 4};
    away.direction = {0, 0, 1};
    away.intensity = 50.f;
    s.lights.push_back(away);
    s.cameras.push_back(make_camera(CameraType::Perspective, {0, -10, 7}, {0, 10, -6.5}, {0, 0, 1}, 0.9));
    return s;
}

TEST(Specialization, LightCullingNeverChangesTheImage) {
    const Scene s = culling_scene();
    const SceneAnalysis a = analyze_scene(s);
    ASSERT_EQ(a.object_count, 10u);  // 8 tiles, 1 sphere, 1 plane
    uint32_t range = 0, cone = 0;
    for (const LightReach& r : a.lights) {
        range += r.culled_range;
        cone += r.culled_cone;
    }
    EXPECT_GT(range, 0u);
    EXPECT_GT(cone, 0u);
    EXPECT_EQ(a.lights[5].objects_reached, 1u);  // the spot pointing away reaches only the infinite plane
    EXPECT_EQ(a.lights[5].culled_cone, 9u);
    // The edge light keeps the tiles under it and the barely lit one beside them.
    const std::span<const uint32_t> tile5 = a.lights_of(5);
    EXPECT_NE(std::find(tile5.begin(), tile5.end(), 2u), tile5.end());
    const std::span<const uint32_t> tile7 = a.lights_of(7);
    EXPECT_EQ(std::find(tile7.begin(), tile7.end(), 2u), tile7.end());
    expect_specialised_equals_general(s, 96);

    // And the culled lights were really skipped per object (same total as the per-point tests).
    RenderSettings rs = small_settings(s, 64);
    const Renderer r(s, rs);
    RenderStats st;
    (void)r.render(&st);
    EXPECT_GT(st.rays.shadow_skipped_unreached, 0u);
}

// ---- analysis flags on chosen assets ----

// The environment's prefiltered levels a render builds: those the used materials' roughness
// reads. Box (untextured, roughness 1) reads the two roughest; a material with a
// metallic-roughness texture can reach roughness 0, so all up to its factor; classic
// materials without a glossy term none.
TEST(SceneAnalysis, PrefilterLevelsFollowTheMaterials) {
    EXPECT_EQ(analyze_scene(load_scene(kAssets + "/gltf/Box/glTF-Binary/Box.glb")).prefilter_levels,
              prefilter_levels_read(1.f, 1.f));
    EXPECT_EQ(analyze_scene(load_scene(kAssets + "/scenes/whitted1980.json")).prefilter_levels, 0u);
    Scene s;
    Material textured;
    textured.roughness = 0.6f;
    textured.metallic_roughness_texture.texture = 0;
    Material smooth;
    smooth.roughness = 0.1f;
    Material unused;
    unused.roughness = 0.9f;
    add_mesh(s, make_quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, add_gltf_material(s, textured)));
    add_mesh(s, make_quad({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, add_gltf_material(s, smooth)));
    add_gltf_material(s, unused);
    EXPECT_EQ(analyze_scene(s).prefilter_levels, prefilter_levels_read(0.f, 0.6f) | prefilter_levels_read(0.1f, 0.1f));
    EXPECT_EQ(analyze_scene(s).prefilter_levels, 0b0111u);
}

TEST(SceneAnalysis, FlagsOfBundledScenes) {
    {
        const SceneAnalysis a = analyze_scene(load_scene(kAssets + "/scenes/whitted1980.json"));
        EXPECT_TRUE(a.features.mirror);
        EXPECT_TRUE(a.features.transmission);
        EXPECT_TRUE(a.features.textured);  // the checkerboard
        EXPECT_FALSE(a.features.opaque());
        EXPECT_FALSE(a.features.vertex_colors);
        EXPECT_FALSE(a.features.alpha_mask);
        // The glass and mirror spheres are constant, the checkered floor varies.
        size_t varying = 0, constant = 0;
        for (const MaterialFeatures& m : a.materials) (m.varying ? varying : constant) += m.used;
        EXPECT_EQ(varying, 1u);
        EXPECT_GE(constant, 2u);
        IntegratorSettings is;
        const KernelFeatures k = select_kernel(a.features, is);
        EXPECT_TRUE(k.transmission && k.mirror && k.attributes && k.tables);
        is.specialize = false;
        EXPECT_EQ(select_kernel(a.features, is), kGeneralKernel);
    }
    {
        const SceneAnalysis a = analyze_scene(load_scene(kAssets + "/gltf/Duck/glTF-Binary/Duck.glb"));
        EXPECT_TRUE(a.features.opaque());
        EXPECT_FALSE(a.features.recursive());
        EXPECT_TRUE(a.features.textured);
        EXPECT_TRUE(a.features.single_sided);
        const KernelFeatures k = select_kernel(a.features, IntegratorSettings{});
        EXPECT_FALSE(k.mirror || k.transmission);
        EXPECT_TRUE(k.attributes);
    }
    {
        const Scene s = load_scene(kAssets + "/gltf/MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb");
        const SceneAnalysis a = analyze_scene(s);
        EXPECT_TRUE(a.features.opaque());
        EXPECT_TRUE(a.features.mirror);  // the smooth spheres
        EXPECT_FALSE(a.features.varying);
        EXPECT_EQ(a.triangles, s.instanced_triangle_count());
        EXPECT_GT(a.scene_bytes, 12u * a.triangles);  // positions and indices at least
        const KernelFeatures k = select_kernel(a.features, IntegratorSettings{});
        EXPECT_TRUE(k.mirror);
        EXPECT_FALSE(k.transmission || k.attributes);
        // With mirrors faded out at any roughness (cutoff 0) nothing reflects: no recursion.
        MappingOptions no_mirrors;
        no_mirrors.mirror_roughness_cutoff = 0.f;
        EXPECT_FALSE(analyze_scene(s, no_mirrors).features.recursive());
    }
    {
        const SceneAnalysis a = analyze_scene(load_scene(kAssets + "/gltf/BoxVertexColors/glTF-Binary/BoxVertexColors.glb"));
        EXPECT_TRUE(a.features.vertex_colors);
        EXPECT_TRUE(a.features.varying);
    }
    {
        const SceneAnalysis a = analyze_scene(load_scene(kAssets + "/gltf/UnlitTest/glTF-Binary/UnlitTest.glb"));
        EXPECT_TRUE(a.features.unlit);
        EXPECT_TRUE(a.features.emissive);
    }
    {
        const SceneAnalysis a = analyze_scene(load_scene(kAssets + "/gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf"));
        EXPECT_TRUE(a.features.alpha_blend);
        EXPECT_FALSE(a.features.opaque());
    }
    {
        const SceneAnalysis a = analyze_scene(load_scene(kAssets + "/gltf/AttenuationTest/glTF-Binary/AttenuationTest.glb"));
        EXPECT_TRUE(a.features.transmission);
        EXPECT_TRUE(a.features.volume);
    }
}

TEST(SceneAnalysis, GltfMirrorAndTransmissionFollowTheMapping) {
    Scene s = gltf_panels(false, false);
    Material& floor = s.materials[0];
    floor.roughness = 1.f;
    EXPECT_FALSE(analyze_scene(s).materials[0].mirror);  // rough: kr faded to 0 at the cutoff 0.3
    floor.roughness = 0.f;
    EXPECT_TRUE(analyze_scene(s).materials[0].mirror);
    floor.roughness = 1.f;
    floor.metallic_roughness_texture.texture = 0;  // roughness = factor x texel can be anything below
    EXPECT_TRUE(analyze_scene(s).materials[0].mirror);
    floor.metallic_roughness_texture.texture = -1;
    floor.transmission = 0.5f;
    EXPECT_TRUE(analyze_scene(s).materials[0].transmission);
    floor.metallic = 1.f;  // a metal transmits nothing
    EXPECT_FALSE(analyze_scene(s).materials[0].transmission);
    floor.unlit = true;
    const MaterialFeatures u = analyze_scene(s).materials[0];
    EXPECT_TRUE(u.unlit && u.emissive);
    EXPECT_FALSE(u.mirror || u.transmission || u.diffuse || u.highlight);
}

// ---- determinism of the specialised kernel across threads and tiles ----

TEST(Specialization, SpecialisedKernelIsDeterministicAcrossThreadsAndTiles) {
    const Scene scene = load_scene(kAssets + "/scenes/default.glb");
    RenderSettings rs = small_settings(scene, 80);
    rs.integrator.min_weight = 1.f / 255.f;
    rs.aa.mode = AaMode::Adaptive;
    rs.threads = 1;
    rs.tile_size = 7;
    const Film a = Renderer(scene, rs).render();
    rs.threads = 2;
    rs.tile_size = 32;
    const Film b = Renderer(scene, rs).render();
    EXPECT_TRUE(same_image(a, b));
}

// SceneView::surface<true> leaves UVs and MIP levels at their defaults for a material that reads
// no texture through UVs (the world-space checker reads p, ng and the footprint): the same
// coefficients as with the UVs computed, while a UV-space checker on the same mesh still gets them.
TEST(SurfaceAttributes, WorldSpaceCheckerSkipsUvsOnly) {
    Scene scene;
    for (const bool world : {true, false}) {
        Texture t;
        t.kind = TextureKind::Checker;
        t.checker.color_a = {0.9f, 0.1f, 0.1f};
        t.checker.color_b = {0.1f, 0.1f, 0.9f};
        t.checker.size = 0.3f;
        t.checker.world_space = world;
        scene.textures.push_back(t);
        WhittedCoeffs c;
        c.kd = Color(0.8f);
        add_classic_material(scene, c, world ? "world" : "uv");
        scene.materials.back().classic_color_texture.texture = int32_t(scene.textures.size() - 1);
    }
    for (uint32_t material : {0u, 1u}) {
        Mesh quad = make_quad({-2.f, 0.f, 2.f}, {2.f, 0.f, 2.f}, {2.f, 0.f, -2.f}, {-2.f, 0.f, -2.f}, material);
        quad.uv0 = {{0.f, 0.f}, {1.f, 0.f}, {1.f, 1.f}, {0.f, 1.f}};
        add_mesh(scene, quad);
    }
    const SceneView view(scene, MappingOptions{});
    Ray ray;
    ray.org = {0.35f, 3.f, 0.2f};
    ray.dir = normalize(Vec3f{0.1f, -1.f, -0.05f});
    const RayCone cone{0.f, 0.01f};
    for (uint32_t mesh : {0u, 1u}) {
        Hit hit;
        hit.geom = mesh;
        hit.inst = mesh;
        hit.prim = 0;
        hit.t = 3.f / -ray.dir.y;
        hit.u = 0.3f;
        hit.v = 0.2f;
        const SurfacePoint sp = view.surface<true>(ray, hit, cone);
        const SurfacePoint flat = view.surface<false>(ray, hit, cone);
        EXPECT_EQ(sp.p, flat.p);
        EXPECT_EQ(sp.ng, flat.ng);
        EXPECT_EQ(sp.ns, flat.ns);
        EXPECT_GT(sp.footprint, 0.f);
        if (mesh == 0) {  // world-space checker: no UVs, no MIP level, and none needed
            EXPECT_EQ(sp.uv[0], (Vec2f{0.f, 0.f}));
            EXPECT_EQ(sp.uv_lod[0], -kInfinity);
            SurfacePoint with_uv = sp;
            with_uv.uv[0] = {0.55f, 0.45f};
            with_uv.uv_lod[0] = -3.f;
            EXPECT_EQ(view.coefficients(sp).kd, view.coefficients(with_uv).kd);
        } else {  // UV-space checker: interpolated UVs and a finite MIP level
            EXPECT_NE(sp.uv[0], (Vec2f{0.f, 0.f}));
            EXPECT_GT(sp.uv_lod[0], -kInfinity);
        }
    }
}

}  // namespace
}  // namespace whitted
