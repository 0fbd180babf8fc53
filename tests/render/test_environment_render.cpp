// The environment through the renderer: the white furnace, what missed rays see, and the same
// environment given by flag (ImportOptions) or by the scene file.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "importers/scene_loader.h"
#include "core/error.h"
#include "integrator/render.h"
#include "scene/scene_builder.h"
#include "shading/environment_map.h"
#include "tests/support/environment_scenes.h"

namespace whitted {
namespace {

namespace fs = std::filesystem;

/// One unit sphere at the origin of material `m`, seen from +Z, under `env`.
Scene sphere_under(const Material& m, const Environment& env, int env_lights) {
    Scene s;
    Sphere sphere;
    sphere.center = {0, 0, 0};
    sphere.radius = 1.0;
    sphere.material = uint32_t(s.materials.size());
    s.materials.push_back(m);
    s.spheres.push_back(sphere);
    s.cameras.push_back(make_camera(CameraType::Perspective, {0, 0, 4}, {0, 0, -1}, {0, 1, 0}, 0.7));
    test::light_with(s, env, env_lights);
    return s;
}

/// sphere_under() with a classic material of coefficients `c`.
Scene sphere_under(const WhittedCoeffs& c, const Environment& env, int env_lights) {
    Material m;
    m.model = MaterialModel::Classic;
    m.classic = c;
    return sphere_under(m, env, env_lights);
}

Film render(const Scene& scene, const IntegratorSettings& integrator = {}) { return test::render_square(scene, integrator); }

using test::constant_environment;
using test::expect_near_rel;
using test::gltf_metal;

// A white diffuse sphere (kd = ka = 1) under a constant environment of radiance L has radiance L:
// it vanishes against the background, whether the light is all ambient or partly extracted.
TEST(EnvironmentRender, WhiteFurnace) {
    const Color L(0.5f, 0.8f, 1.2f);
    WhittedCoeffs white;
    white.kd = white.ka = Color(1.f);
    for (int lights : {0, 1, 16}) {
        SCOPED_TRACE("env lights " + std::to_string(lights));
        const Film film = render(sphere_under(white, constant_environment(L), lights));
        expect_near_rel(film.beauty[film.index(16, 16)], L, 0.01f);  // the sphere's centre
        expect_near_rel(film.beauty[film.index(12, 20)], L, 0.01f);  // off centre, still on it
        expect_near_rel(film.beauty[film.index(0, 0)], L, 1e-5f);    // a miss sees the map
    }
}

// A mirror reflects the environment; a hidden environment (a background given) still lights and
// is still reflected, only camera rays that miss show the background.
TEST(EnvironmentRender, MissedRaysSeeTheEnvironment) {
    const Color L(0.25f, 0.5f, 0.75f);
    WhittedCoeffs mirror;
    mirror.kr = Color(1.f);
    const Scene scene = sphere_under(mirror, constant_environment(L), 0);
    IntegratorSettings hidden;
    hidden.background = Color(0.f, 1.f, 0.f);
    hidden.environment_visible = false;
    for (const IntegratorSettings& settings : {IntegratorSettings{}, hidden}) {
        const Film film = render(scene, settings);
        expect_near_rel(film.beauty[film.index(16, 16)], L, 1e-5f);
    }
    const Film film = render(scene, hidden);
    EXPECT_EQ(film.beauty[film.index(0, 0)], hidden.background);
}

// The constant ambient replaces the environment's when asked (an `ambient` given).
TEST(EnvironmentRender, ConstantAmbientWhenGiven) {
    WhittedCoeffs ambient_only;
    ambient_only.ka = Color(1.f);
    const Scene scene = sphere_under(ambient_only, constant_environment(Color(2.f)), 0);
    IntegratorSettings constant;
    constant.ambient = Color(0.25f);
    constant.environment_ambient = false;
    expect_near_rel(render(scene).beauty[16 * 32 + 16], Color(2.f), 0.01f);
    EXPECT_EQ(render(scene, constant).beauty[16 * 32 + 16], Color(0.25f));
}

// Ward's adaptive shadow testing of the extracted lights: shadow rays stop once what the untested
// lights could still add is below min_weight, and those are added at the visibility of the tested
// ones. So the CLI's 1/255 gives the image of min_weight 0 within 1/255 in every channel, with a
// sphere shadowing a floor, while tracing fewer shadow rays; nothing is dropped (a lit point that
// tested no light at all still gets its light).
TEST(EnvironmentRender, DimLightsSkippedWithinMinWeight) {
    WhittedCoeffs white;
    white.kd = white.ka = Color(0.8f);
    Environment env;
    auto image = std::make_shared<EnvironmentImage>();
    image->width = 64;
    image->height = 32;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 64; ++x) image->texels.push_back(Color(0.05f + 0.9f * float((x * 7 + y * 13) % 17) / 16.f));
    env.image = image;
    Scene scene = sphere_under(white, env, 1024);
    add_mesh(scene, make_quad({-4, -1, -4}, {-4, -1, 4}, {4, -1, 4}, {4, -1, -4}, scene.spheres[0].material));
    scene.cameras[0] = make_camera(CameraType::Perspective, {0, 1.5, 4}, normalize(Vec3d(0, -0.5, -1)), {0, 1, 0}, 0.9);
    RenderSettings rs;
    rs.width = rs.height = 32;
    rs.threads = 1;
    rs.integrator.env_occlusion = 0;  // the lights' shadow test alone (occlusion: test_environment_occlusion.cpp)
    RenderStats exact_stats, cut_stats;
    const Film a = Renderer(scene, rs).render(&exact_stats);
    rs.integrator.min_weight = 1.f / 255.f;
    const Film b = Renderer(scene, rs).render(&cut_stats);
    float worst = 0.f;
    for (size_t i = 0; i < a.beauty.size(); ++i)
        for (int k = 0; k < 3; ++k) worst = std::max(worst, std::fabs(a.beauty[i][k] - b.beauty[i][k]));
    EXPECT_LE(worst, 1.f / 255.f);
    EXPECT_GT(worst, 0.f);  // the floor's shadow is estimated, not traced, for the untested lights
    EXPECT_EQ(exact_stats.rays.shadow_skipped_dim, 0u);
    EXPECT_GT(cut_stats.rays.shadow_skipped_dim, 0u);
    EXPECT_LT(cut_stats.rays.shadow, exact_stats.rays.shadow);
    std::printf("[ ward ] shadow rays %llu -> %llu, worst difference %.5f\n",
                (unsigned long long)exact_stats.rays.shadow,
                (unsigned long long)cut_stats.rays.shadow, double(worst));
}

// A rough metal (roughness 1, past the mirror cutoff) reflects the environment through the
// prefiltered map: under a constant environment L it shows base colour * L, in the kernel without
// recursion that an opaque scene without mirrors selects.
TEST(EnvironmentRender, RoughMetalReflectsTheEnvironment) {
    const Color L(0.5f, 0.8f, 1.2f), base(0.9f, 0.6f, 0.3f);
    const Scene scene = sphere_under(gltf_metal(base, 1.f), constant_environment(L), kDefaultEnvironmentLights);
    RenderSettings rs;
    rs.width = rs.height = 32;
    rs.threads = 1;
    const Renderer renderer(scene, rs);
    EXPECT_FALSE(renderer.kernel().mirror) << kernel_name(renderer.kernel());
    const Film film = renderer.render();
    expect_near_rel(film.beauty[film.index(16, 16)], base * L, 0.02f);
    expect_near_rel(film.beauty[film.index(12, 20)], base * L, 0.02f);
    // Without an environment the glossy term is 0: a black metal under the ambient's ka = 0.
    Scene plain = scene;
    plain.environment.reset();
    EXPECT_EQ(render(plain).beauty[film.index(16, 16)], Color(0.f));
}

/// A lat-long of 128 x 64 texels, black but for a sun of radiance `sun` within 10 degrees of +Z.
Environment sun_environment(float sun) {
    auto image = std::make_shared<EnvironmentImage>();
    image->name = "sun";
    image->width = 128;
    image->height = 64;
    image->texels.assign(128 * 64, Color(0.f));
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 128; ++x) {
            const Vec3f d = latlong_direction((float(x) + 0.5f) / 128.f, (float(y) + 0.5f) / 64.f);
            if (d.z > std::cos(10.f * kPi / 180.f)) image->texels[size_t(y) * 128 + size_t(x)] = Color(sun);
        }
    Environment env;
    env.image = image;
    return env;
}

/// Sum of the film's beauty over all pixels.
Color film_sum(const Film& film) {
    Vec3d sum(0.0);
    for (const Color& c : film.beauty) sum += Vec3d(c);
    return Color(sum);
}

// The sun behind the camera, reflected by a sphere, arrives once: whether it stays in the map
// (0 lights) or becomes a light with a highlight (1 light), the sphere reflects the same energy.
// Mirrors see the whole map (their highlight carries almost none of the sun's light); rough
// surfaces read the residual for the share their highlight carries. Past roughness 0.63 the
// highlight, (N.H)^n without N.L, no longer stands for the lobe (unscaled it reflected 1.6x the
// sun at 0.75, 2.6x at 1): the prefiltered map takes the extracted light's reflection back.
TEST(EnvironmentRender, ExtractedLightIsNotCountedTwice) {
    const Environment env = sun_environment(50.f);
    WhittedCoeffs mirror;
    mirror.kr = mirror.ks = Color(1.f);
    mirror.n = 10000.f;
    struct Case {
        std::string name;
        Material m;
    };
    Material classic_mirror;
    classic_mirror.model = MaterialModel::Classic;
    classic_mirror.classic = mirror;
    const Case cases[] = {{"mirror", classic_mirror},
                          {"metal r=0.4", gltf_metal(Color(1.f), 0.4f)},
                          {"metal r=0.5", gltf_metal(Color(1.f), 0.5f)},
                          {"metal r=0.75", gltf_metal(Color(1.f), 0.75f)},
                          {"metal r=1", gltf_metal(Color(1.f), 1.f)}};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const Scene one_light = sphere_under(c.m, env, 1);
        ASSERT_EQ(one_light.lights.size(), 1u);
        const float zero = film_sum(render(sphere_under(c.m, env, 0))).y, one = film_sum(render(one_light)).y;
        std::printf("[ sun ] %s: reflected energy %.1f without the light, %.1f with it\n", c.name.c_str(), zero, one);
        EXPECT_NEAR(one, zero, 0.1f * zero);
    }
}

/// A scene file with a plane, a sphere and a light, and optionally an environment entry.
fs::path write_scene(const fs::path& dir, const std::string& name, const std::string& environment) {
    const fs::path path = dir / name;
    std::ofstream out(path);
    out << R"({"version": 1,
      "camera": {"type": "perspective", "position": [0, 1, 4], "look_at": [0, 0.5, 0], "up": [0, 1, 0], "fov": 40},
      "materials": {"white": {"kd": 0.7, "ka": 0.7, "ks": 0.3, "n": 40, "kr": 0.2}},
      "objects": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "u_axis": [1, 0, 0], "material": "white"},
                  {"type": "sphere", "center": [0, 0.6, 0], "radius": 0.6, "material": "white"}],
      "lights": [{"type": "point", "position": [2, 4, 3], "intensity": 6}])"
        << environment << "}\n";
    return path;
}

fs::path temp_dir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("whitted_env_" + name + "_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    return dir;
}

const std::string kCourtyard = std::string(WHITTED_SOURCE_DIR) + "/assets/environments/courtyard.exr";

// The same environment from the flag or from the scene file gives the same image, bit for bit.
TEST(EnvironmentRender, FlagAndSceneFileAgree) {
    const fs::path dir = temp_dir("agree");
    const fs::path plain = write_scene(dir, "plain.json", "");
    const fs::path named = write_scene(dir, "named.json",
                                       R"(, "environment": {"file": ")" + kCourtyard + R"(", "rotation": 90, "exposure": -1})");
    ImportOptions flag;
    flag.environment = "courtyard";
    flag.environment_rotation = 90.f;
    flag.environment_exposure = -1.f;
    const Scene a = load_scene(plain.string(), flag);
    const Scene b = load_scene(named.string());
    ASSERT_TRUE(a.environment && b.environment);
    EXPECT_EQ(a.lights.size(), b.lights.size());
    const Film fa = render(a), fb = render(b);
    ASSERT_EQ(fa.beauty.size(), fb.beauty.size());
    size_t differ = 0;
    for (size_t i = 0; i < fa.beauty.size(); ++i) differ += !(fa.beauty[i] == fb.beauty[i]);
    EXPECT_EQ(differ, 0u);
    // And the environment changes the image (it is not ignored).
    const Film fc = render(load_scene(plain.string()));
    size_t changed = 0;
    for (size_t i = 0; i < fa.beauty.size(); ++i) changed += !(fa.beauty[i] == fc.beauty[i]);
    EXPECT_GT(changed, fa.beauty.size() / 2);
    // --no-environment removes it again.
    ImportOptions none;
    none.no_environment = true;
    EXPECT_FALSE(load_scene(named.string(), none).environment);
    fs::remove_all(dir);
}

// A map that cannot be read is one error naming it (and the scene file's pointer).
TEST(EnvironmentRender, MissingMapIsALocatedError) {
    const fs::path dir = temp_dir("missing");
    const fs::path plain = write_scene(dir, "plain.json", "");
    ImportOptions flag;
    flag.environment = (dir / "nowhere.exr").string();
    try {
        load_scene(plain.string(), flag);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("nowhere.exr"), std::string::npos) << e.what();
    }
    const fs::path named = write_scene(dir, "named.json", R"(, "environment": {"file": "nowhere.exr"})");
    try {
        load_scene(named.string());
        FAIL() << "no error";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("/environment/file"), std::string::npos) << what;
        EXPECT_NE(what.find("nowhere.exr"), std::string::npos) << what;
    }
    fs::remove_all(dir);
}

}  // namespace
}  // namespace whitted
