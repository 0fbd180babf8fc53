// `whitted info` text (describe_scene): stable, one greppable record per line.

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "importers/scene_report.h"
#include "tests/support/test_importer_util.h"

namespace whitted::test {
namespace {

std::vector<std::string> lines_starting_with(const std::string& text, const std::string& prefix) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
        if (line.rfind(prefix, 0) == 0) out.push_back(line);
    return out;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(SceneReport, CountsCamerasMaterialsAndWarnings) {
    ImportOptions default_light;
    default_light.default_environment = false;
    const Scene s = load_scene(asset("Cameras/glTF/Cameras.gltf"), default_light);
    const std::string text = describe_scene(s);
    EXPECT_EQ(text, describe_scene(s));  // stable
    const auto counts = lines_starting_with(text, "counts: ");
    ASSERT_EQ(counts.size(), 1u);
    EXPECT_TRUE(contains(counts[0],
                         "meshes=1 triangles=2 instanced_triangles=2 instances=1 spheres=0 quadrics=0 materials=1 "
                         "textures=0 lights=1 cameras=2"))
        << counts[0];
    const auto cams = lines_starting_with(text, "camera[");
    ASSERT_EQ(cams.size(), 2u);
    EXPECT_TRUE(contains(cams[0], "type=perspective yfov=0.7 "));
    EXPECT_TRUE(contains(cams[0], "aspect=1 znear=0.01 zfar=100 position=(0.5, 0.5, 3) forward=(0, 0, -1) default=no"))
        << cams[0];
    EXPECT_TRUE(contains(cams[1], "type=orthographic xmag=1 ymag=1"));
    // The default light, its warning, and the default material with its mapped coefficients.
    const auto lights = lines_starting_with(text, "light[0]: ");
    ASSERT_EQ(lights.size(), 1u);
    EXPECT_TRUE(contains(lights[0], "type=directional")) << lights[0];
    EXPECT_TRUE(contains(lights[0], "intensity=1 "));
    EXPECT_TRUE(contains(lights[0], "default=yes"));
    EXPECT_EQ(lines_starting_with(text, "warning: no lights in the file").size(), 1u);
    EXPECT_EQ(lines_starting_with(text, "material[0]: name=\"default\"").size(), 1u);
    EXPECT_EQ(lines_starting_with(text, "material[0] whitted: kd=").size(), 1u);
    EXPECT_EQ(lines_starting_with(text, "material[0] textures: none").size(), 1u);
    EXPECT_EQ(text.back(), '\n');
}

TEST(SceneReport, LightsTexturesAndExtensions) {
    const Scene s = load_scene(asset("LightsPunctualLamp/glTF/LightsPunctualLamp.gltf"), no_textures());
    const std::string text = describe_scene(s);
    const auto lights = lines_starting_with(text, "light[");
    ASSERT_EQ(lights.size(), 5u);
    EXPECT_TRUE(contains(lights[0], "name=\"Point\" type=point color=(1, 0.631875, 0.2391) intensity=15 range=inf"))
        << lights[0];
    EXPECT_TRUE(contains(lights[0], "attenuation=inverse-square default=no"));
    EXPECT_EQ(lines_starting_with(text, "texture[").size(), 7u);
    EXPECT_TRUE(contains(text, "texture[0]: name=\"material0_basecolor.jpeg\" size=not-loaded levels=0 srgb=yes"));
    EXPECT_TRUE(contains(text, "extension: KHR_lights_punctual supported required=no"));
    EXPECT_TRUE(contains(text, "extension: KHR_materials_transmission supported required=no"));
    EXPECT_TRUE(contains(text,
                         "material[2] textures: base_color=tex0(uv0) metallic_roughness=tex1(uv0) "
                         "normal=tex2(uv0, scale 1) emissive=tex3(uv0) transmission=tex6(uv0)"));
    EXPECT_EQ(lines_starting_with(text, "warning: no cameras in the scene").size(), 1u);
}

TEST(SceneReport, TextureTransformIsShown) {
    const Scene s = load_scene(asset("TextureTransformTest/glTF/TextureTransformTest.gltf"), no_textures());
    const std::string text = describe_scene(s);
    EXPECT_TRUE(contains(text, "base_color=tex1(uv0, offset (-0.2, -0.1) rotation 0.3 scale (1.5, 1.5))")) << text;
}

}  // namespace
}  // namespace whitted::test

namespace whitted::test {
namespace {

// `whitted info` of a file lit by an environment says so: its size, its lights, its ambient.
TEST(SceneReport, EnvironmentLightsAndAmbient) {
    ImportOptions o;
    o.environment = "courtyard";
    o.environment_lights = 4;
    const std::string text = describe_scene(load_scene(asset("Box/glTF/Box.gltf"), o));
    const auto env = lines_starting_with(text, "environment: ");
    ASSERT_EQ(env.size(), 1u) << text;
    EXPECT_TRUE(contains(env[0], "name=\"courtyard\" size=1024x512 rotation=0 exposure=0 visible=yes lights=4"))
        << env[0];
    EXPECT_EQ(lines_starting_with(text, "environment ambient: +X=").size(), 1u);
    // Summarised: the four lights by their share, not a line each.
    EXPECT_EQ(lines_starting_with(text, "environment light[").size(), 4u) << text;
    EXPECT_EQ(lines_starting_with(text, "light[3]: ").size(), 0u) << text;
    const std::string verbose = describe_scene(load_scene(asset("Box/glTF/Box.gltf"), o), ReportDetail::Verbose);
    EXPECT_EQ(lines_starting_with(verbose, "light[3]: name=\"environment light 3\" type=directional").size(), 1u);
}

/// The number of lines of `text`.
size_t line_count(const std::string& text) { return size_t(std::count(text.begin(), text.end(), '\n')); }

/// The value of `key=` in `line` up to the next space (empty when absent).
std::string field(const std::string& line, const std::string& key) {
    const size_t at = line.find(" " + key + "=");
    if (at == std::string::npos) return {};
    const size_t from = at + key.size() + 2;
    return line.substr(from, line.find(' ', from) - from);
}

// Hundreds of extracted lights fit a screen: the environment line gives their count and share of the
// map's power, the brightest few follow, most powerful first; --verbose lists every one.
TEST(SceneReport, ManyEnvironmentLightsAreSummarised) {
    ImportOptions o;
    o.environment = "studio";
    o.environment_lights = 256;
    const Scene scene = load_scene(asset("Box/glTF/Box.gltf"), o);
    size_t extracted = 0;
    for (const Light& l : scene.lights) extracted += l.from_environment;
    ASSERT_GT(extracted, kBrightestEnvironmentLights);
    const std::string text = describe_scene(scene);
    EXPECT_LE(line_count(text), 60u) << text;
    const auto env = lines_starting_with(text, "environment: ");
    ASSERT_EQ(env.size(), 1u);
    EXPECT_EQ(field(env[0], "lights"), std::to_string(extracted)) << env[0];
    const std::string share = field(env[0], "lights_share");
    ASSERT_FALSE(share.empty()) << env[0];
    const double percent = std::stod(share);
    EXPECT_GT(percent, 50.0) << env[0];  // the threshold leaves the ambient at most 1/16 of the light
    EXPECT_LE(percent, 100.0) << env[0];
    const auto brightest = lines_starting_with(text, "environment light[");
    ASSERT_EQ(brightest.size(), kBrightestEnvironmentLights);
    double previous = 101.0, sum = 0.0;
    for (const std::string& l : brightest) {
        const std::string s = field(l, "share_of_lights");
        ASSERT_FALSE(s.empty()) << l;
        const double v = std::stod(s.substr(0, s.size() - 1));
        EXPECT_LE(v, previous) << l;  // most powerful first
        previous = v;
        sum += v;
    }
    EXPECT_LE(sum, 100.5);
    EXPECT_EQ(lines_starting_with(text, "environment lights: ").size(), 1u) << text;
    EXPECT_EQ(lines_starting_with(text, "analysis light[").size(), 0u) << text;

    const std::string verbose = describe_scene(scene, ReportDetail::Verbose);
    EXPECT_EQ(lines_starting_with(verbose, "light[").size(), scene.lights.size());
    EXPECT_EQ(lines_starting_with(verbose, "analysis light[").size(), scene.lights.size());
    EXPECT_EQ(lines_starting_with(verbose, "environment light[").size(), 0u);
}

}  // namespace
}  // namespace whitted::test
