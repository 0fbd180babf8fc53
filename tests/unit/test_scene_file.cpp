// The JSON scene file (docs/scene-format.md): every key lands in the right Scene field, every
// error class names the file, the JSON pointer and line:column, includes compose with glTF.

#include <cmath>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "importers/scene_file.h"
#include "importers/scene_file_json.h"
#include "importers/scene_loader.h"
#include "importers/scene_report.h"
#include "core/error.h"
#include "tests/support/test_importer_util.h"

namespace whitted::test {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

std::string fixture(const std::string& name) { return std::string(WHITTED_TEST_DATA_DIR) + "/scene-files/" + name; }
std::string gltf_dir() { return std::string(WHITTED_ASSETS_DIR) + "/gltf"; }

/// Writes `json` as scratch/<name> and imports it.
Scene load_json(const std::string& json, const ImportOptions& options = {}, const std::string& name = "scene.json") {
    return import_scene_file(write_file(name, json), options);
}

/// `{"version": 1, <body>}`.
std::string doc(const std::string& body) { return std::string("{\"version\": 1") + (body.empty() ? "" : ", ") + body + "}"; }

/// The whitted::Error a scene throws (fails the test when it does not throw).
Error error_of(const std::string& json, const ImportOptions& options = {}, const std::string& name = "bad.json") {
    const std::string path = write_file(name, json);
    try {
        import_scene_file(path, options);
    } catch (const Error& e) {
        return e;
    }
    ADD_FAILURE() << "no error for: " << json;
    return Error("no error");
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

#define EXPECT_CONTAINS(text, part) EXPECT_TRUE(contains((text), (part))) << "in: " << (text)

void expect_vec(const Vec3d& a, const Vec3d& b, double eps = 1e-9) {
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
    EXPECT_NEAR(a.z, b.z, eps);
}
void expect_vec(const Vec3f& a, const Vec3f& b, float eps = 1e-6f) {
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
    EXPECT_NEAR(a.z, b.z, eps);
}
void expect_mat(const Mat4d& a, const Mat4d& b, double eps = 1e-9) {
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) EXPECT_NEAR(a(r, c), b(r, c), eps) << "at (" << r << ", " << c << ")";
}

const Material& material_named(const Scene& s, const std::string& name) {
    for (const Material& m : s.materials)
        if (m.name == name) return m;
    ADD_FAILURE() << "no material " << name;
    return s.materials.at(0);
}

// ---------------------------------------------------------------------------------------------
// Every key, one area per test

TEST(SceneFile, RenderSettingsAndAmbient) {
    const Scene s = load_json(doc(R"("ambient": [0.1, 0.2, 0.3],
      "render": {"width": 640, "height": 480, "aa": "stratified", "aa_threshold": 0.05, "aa_depth": 2, "spp": 16,
                 "max_depth": 7, "min_weight": 0.004, "background": [0.1, 0.2, 0.6], "exposure": -1.5,
                 "fresnel": true, "output": "out/x.png", "view": "Raw", "display": "sRGB", "camera": 0})"));
    const SceneRenderSettings& r = s.settings;
    EXPECT_EQ(r.width, 640);
    EXPECT_EQ(r.height, 480);
    EXPECT_EQ(r.aa, "stratified");
    EXPECT_FLOAT_EQ(*r.aa_threshold, 0.05f);
    EXPECT_EQ(r.aa_depth, 2);
    EXPECT_EQ(r.spp, 16);
    EXPECT_EQ(r.max_depth, 7);
    EXPECT_FLOAT_EQ(*r.min_weight, 0.004f);
    expect_vec(*r.background, Color(0.1f, 0.2f, 0.6f));
    expect_vec(*r.ambient, Color(0.1f, 0.2f, 0.3f));
    EXPECT_FLOAT_EQ(*r.exposure, -1.5f);
    EXPECT_EQ(r.fresnel, true);
    EXPECT_EQ(r.output, "out/x.png");  // stored as given (the CLI resolves it)
    EXPECT_EQ(r.view, "Raw");
    EXPECT_EQ(r.display, "sRGB");
    EXPECT_EQ(r.camera, 0);
    // A gray number is a color too; unset settings stay unset.
    const Scene g = load_json(doc(R"("render": {"background": 0.5})"));
    expect_vec(*g.settings.background, Color(0.5f));
    EXPECT_FALSE(g.settings.width.has_value());
    EXPECT_FALSE(g.settings.ambient.has_value());
    EXPECT_FALSE(load_json(doc("")).settings.aa.has_value());
}

TEST(SceneFile, PerspectiveCamera) {
    const Scene s = load_json(doc(R"("camera": {"type": "perspective", "name": "cam", "position": [0, 1, 5],
      "look_at": [0, 1, 0], "up": [0, 1, 0], "fov": 40, "znear": 0.01, "zfar": 100})"));
    ASSERT_EQ(s.cameras.size(), 1u);
    const Camera& c = s.cameras[0];
    EXPECT_EQ(c.name, "cam");
    EXPECT_EQ(c.type, CameraType::Perspective);
    EXPECT_NEAR(c.yfov, 40 * kDeg, 1e-12);
    EXPECT_EQ(c.aspect, 0.0);
    EXPECT_DOUBLE_EQ(c.znear, 0.01);
    EXPECT_DOUBLE_EQ(c.zfar, 100.0);
    EXPECT_FALSE(c.is_default);
    // Looks down -Z (towards look_at), +Y up, positioned at `position`.
    expect_vec(c.world_from_camera.apply_point({0, 0, 0}), {0, 1, 5});
    expect_vec(c.world_from_camera.apply_vector({0, 0, -1}), {0, 0, -1});
    expect_vec(c.world_from_camera.apply_vector({0, 1, 0}), {0, 1, 0});
    expect_vec(c.world_from_camera.apply_vector({1, 0, 0}), {1, 0, 0});
    // Defaults: perspective, fov 45, direction -Z.
    const Scene d = load_json(doc(R"("camera": {"position": [1, 2, 3]})"));
    EXPECT_NEAR(d.cameras[0].yfov, 45 * kDeg, 1e-12);
    expect_vec(d.cameras[0].world_from_camera.apply_vector({0, 0, -1}), {0, 0, -1});
    EXPECT_EQ(d.cameras[0].name, "camera");
}

TEST(SceneFile, OrthographicCameraAndCameraList) {
    const Scene s = load_json(doc(R"("camera": [
      {"position": [0, 0, 5]},
      {"type": "orthographic", "name": "top", "position": [0, 10, 0], "direction": [0, -1, 0], "up": [0, 0, -1], "size": 8}])"));
    ASSERT_EQ(s.cameras.size(), 2u);
    EXPECT_EQ(s.cameras[0].name, "camera 0");
    const Camera& c = s.cameras[1];
    EXPECT_EQ(c.type, CameraType::Orthographic);
    EXPECT_DOUBLE_EQ(c.ymag, 4.0);  // size = full vertical extent
    EXPECT_EQ(c.aspect, 0.0);       // xmag follows the image aspect at render time
    expect_vec(c.world_from_camera.apply_vector({0, 0, -1}), {0, -1, 0});
    expect_vec(c.world_from_camera.apply_vector({0, 1, 0}), {0, 0, -1});
}

TEST(SceneFile, CheckerAndImageTextures) {
    // A 2x1 RGB PNG (red, blue) next to the scene file.
    std::filesystem::copy_file(fixture("red_blue_2x1.png"), scratch_dir() / "tex_2x1.png",
                               std::filesystem::copy_options::overwrite_existing);
    const std::string json = doc(R"(
      "textures": {
        "checks": {"type": "checker", "colors": [[1, 0, 0], 0.5], "size": 0.25, "space": "world"},
        "uvchecks": {"type": "checker"},
        "img": {"type": "image", "file": "tex_2x1.png", "srgb": false, "wrap": "mirror", "filter": "nearest",
                "uv_set": 1, "uv_transform": {"offset": [0.5, 0.25], "rotation": 90, "scale": 2}},
        "img2": {"type": "image", "file": "tex_2x1.png", "mipmaps": false}
      },
      "materials": {"a": {"kd": "checks"}, "b": {"kd": "img"}, "c": {"ka": "uvchecks"}, "d": {"kd": "img2"}})");
    const Scene s = load_json(json);
    ASSERT_EQ(s.textures.size(), 4u);
    // File order is kept (nlohmann sorts keys; the importer does not).
    const Texture& ch = s.textures[0];
    EXPECT_EQ(ch.name, "checks");
    EXPECT_EQ(ch.kind, TextureKind::Checker);
    expect_vec(ch.checker.color_a, Color(1, 0, 0));
    expect_vec(ch.checker.color_b, Color(0.5f));
    EXPECT_FLOAT_EQ(ch.checker.size, 0.25f);
    EXPECT_TRUE(ch.checker.world_space);
    EXPECT_EQ(ch.image, -1);
    const Texture& uv = s.textures[1];
    EXPECT_EQ(uv.kind, TextureKind::Checker);
    EXPECT_FALSE(uv.checker.world_space);  // default "uv"
    expect_vec(uv.checker.color_a, Color(1.f));
    expect_vec(uv.checker.color_b, Color(0.f));
    EXPECT_FLOAT_EQ(uv.checker.size, 1.f);
    const Texture& img = s.textures[2];
    EXPECT_EQ(img.kind, TextureKind::Image);
    EXPECT_EQ(img.name, "img");  // the texture's key, as for checkers
    EXPECT_FALSE(img.srgb);
    EXPECT_EQ(img.wrap_s, WrapMode::MirroredRepeat);
    EXPECT_EQ(img.wrap_t, WrapMode::MirroredRepeat);
    EXPECT_EQ(img.mag_filter, FilterMode::Nearest);
    EXPECT_EQ(img.min_filter, FilterMode::Nearest);
    ASSERT_EQ(img.levels.size(), 2u);  // 2x1 and its 1x1 MIP
    EXPECT_EQ(img.levels[0].width, 2);
    EXPECT_EQ(img.levels[0].height, 1);
    EXPECT_EQ(img.levels[0].texels, (std::vector<uint8_t>{255, 0, 0, 255, 0, 0, 255, 255}));
    EXPECT_TRUE(s.textures[3].srgb);  // default for color data
    EXPECT_FALSE(s.textures[3].use_mips);
    EXPECT_EQ(s.textures[3].levels.size(), 1u);
    // The material's reference carries the texture's UV set and transform.
    const TextureRef& ref = material_named(s, "b").classic_color_texture;
    EXPECT_EQ(ref.texture, 2);
    EXPECT_EQ(ref.uv_set, 1u);
    EXPECT_FLOAT_EQ(ref.transform.offset.x, 0.5f);
    EXPECT_FLOAT_EQ(ref.transform.offset.y, 0.25f);
    EXPECT_NEAR(ref.transform.rotation, std::numbers::pi / 2, 1e-6);
    EXPECT_FLOAT_EQ(ref.transform.scale.x, 2.f);
    EXPECT_FLOAT_EQ(ref.transform.scale.y, 2.f);
    // load_textures = false: the file must exist, its texels are not read.
    const Scene fast = load_json(json, no_textures());
    EXPECT_TRUE(fast.textures[2].levels.empty());
}

TEST(SceneFile, MaterialCoefficients) {
    const Scene s = load_json(doc(R"("textures": {"t": {"type": "checker"}, "u": {"type": "checker"}},
      "materials": {
        "defaults": {},
        "glass": {"kd": 0, "ks": 0.1, "n": 200, "kr": 0.2, "kt": 0.7, "ior": 1.33, "thin": true,
                  "absorption": [0.1, 0.2, 0.3]},
        "mirror": {"kd": 0.05, "ks": [0.8, 0.7, 0.6], "n": 100},
        "split": {"color": [0.5, 0.4, 0.3], "ks": 0.8, "highlight": 0.3, "ka": 0.1},
        "floor": {"kd": "t", "ka": 0.2},
        "amb": {"kd": 0.5, "ka": "u"},
        "lamp": {"emission": [4, 4, 4]}
      })"));
    ASSERT_EQ(s.materials.size(), 7u);  // file order, no default material needed
    EXPECT_EQ(s.materials[0].name, "defaults");
    EXPECT_EQ(s.materials[6].name, "lamp");
    for (const Material& m : s.materials) EXPECT_EQ(m.model, MaterialModel::Classic) << m.name;

    const WhittedCoeffs& d = material_named(s, "defaults").classic;
    expect_vec(d.kd, Color(0.f));
    expect_vec(d.ka, Color(0.f));
    expect_vec(d.ks, Color(0.f));
    EXPECT_FLOAT_EQ(d.n, 32.f);
    expect_vec(d.kr, Color(0.f));
    expect_vec(d.kt, Color(0.f));
    EXPECT_FLOAT_EQ(d.ior, 1.5f);
    EXPECT_FALSE(d.thin);
    expect_vec(d.emission, Color(0.f));
    expect_vec(d.absorption, Color(0.f));
    EXPECT_FALSE(material_named(s, "defaults").classic_color_texture.valid());

    const WhittedCoeffs& g = material_named(s, "glass").classic;
    expect_vec(g.ks, Color(0.1f));
    expect_vec(g.kr, Color(0.2f));  // kr overrides the mirror weight only
    expect_vec(g.kt, Color(0.7f));
    EXPECT_FLOAT_EQ(g.n, 200.f);
    EXPECT_FLOAT_EQ(g.ior, 1.33f);
    EXPECT_TRUE(g.thin);
    expect_vec(g.absorption, Color(0.1f, 0.2f, 0.3f));

    const WhittedCoeffs& m = material_named(s, "mirror").classic;
    expect_vec(m.kd, Color(0.05f));
    expect_vec(m.ka, Color(0.05f));  // ka defaults to kd
    expect_vec(m.ks, Color(0.8f, 0.7f, 0.6f));
    expect_vec(m.kr, Color(0.8f, 0.7f, 0.6f));  // Whitted's single ks weights both

    const WhittedCoeffs& sp = material_named(s, "split").classic;
    expect_vec(sp.kd, Color(0.5f, 0.4f, 0.3f));  // color = kd
    expect_vec(sp.ka, Color(0.1f));
    expect_vec(sp.ks, Color(0.3f));  // highlight overrides the highlight only
    expect_vec(sp.kr, Color(0.8f));

    const Material& f = material_named(s, "floor");
    expect_vec(f.classic.kd, Color(1.f));  // texture: coefficient 1
    expect_vec(f.classic.ka, Color(0.2f));
    EXPECT_EQ(f.classic_color_texture.texture, 0);
    const Material& a = material_named(s, "amb");
    expect_vec(a.classic.kd, Color(0.5f));
    expect_vec(a.classic.ka, Color(1.f));
    EXPECT_EQ(a.classic_color_texture.texture, 1);

    expect_vec(material_named(s, "lamp").classic.emission, Color(4.f));
    // Only "split" (kd 0.5 + kr 0.8) returns more than it receives.
    std::vector<std::string> energy;
    for (const std::string& w : s.warnings)
        if (contains(w, "kd + kr + kt")) energy.push_back(w);
    ASSERT_EQ(energy.size(), 1u);
    EXPECT_CONTAINS(energy[0], "/materials/split: material 'split': kd + kr + kt = 1.3 > 1 (red channel)");
}

TEST(SceneFile, KdTextureAlsoSetsKa) {
    const Scene s = load_json(doc(R"("textures": {"t": {"type": "checker"}}, "materials": {"m": {"kd": "t"}})"));
    const Material& m = s.materials[0];
    expect_vec(m.classic.kd, Color(1.f));
    expect_vec(m.classic.ka, Color(1.f));
    EXPECT_EQ(m.classic_color_texture.texture, 0);
}

TEST(SceneFile, EnergyWarning) {
    const Scene s = load_json(doc(R"("materials": {"hot": {"kd": 0.6, "ks": 0.3, "kt": [0.2, 0, 0]}})"));
    ASSERT_FALSE(s.warnings.empty());
    EXPECT_CONTAINS(s.warnings[0], "material 'hot': kd + kr + kt = 1.1 > 1 (red channel)");
}

TEST(SceneFile, SpheresAndDefaultMaterial) {
    const Scene s = load_json(doc(R"("materials": {"m": {"kd": 1}}, "objects": [
      {"type": "sphere", "name": "ball", "center": [1, 2, 3], "radius": 0.5, "material": "m"},
      {"type": "sphere", "center": [0, 0, 0], "radius": 2}])"));
    ASSERT_EQ(s.spheres.size(), 2u);
    EXPECT_EQ(s.spheres[0].name, "ball");
    expect_vec(s.spheres[0].center, {1, 2, 3});
    EXPECT_DOUBLE_EQ(s.spheres[0].radius, 0.5);
    EXPECT_EQ(s.spheres[0].material, 0u);
    EXPECT_EQ(s.spheres[1].name, "sphere 1");
    // No "material": the built-in default (classic, kd 0.8), added once.
    ASSERT_EQ(s.materials.size(), 2u);
    EXPECT_EQ(s.spheres[1].material, 1u);
    EXPECT_EQ(s.materials[1].name, "default");
    EXPECT_EQ(s.materials[1].model, MaterialModel::Classic);
    expect_vec(s.materials[1].classic.kd, Color(0.8f));
    // A file's own "default" material is used instead.
    const Scene u = load_json(doc(R"("materials": {"default": {"kd": 0.3}}, "objects": [
      {"type": "sphere", "center": [0, 0, 0], "radius": 2}])"));
    ASSERT_EQ(u.materials.size(), 1u);
    EXPECT_EQ(u.spheres[0].material, 0u);
    // Never empty.
    EXPECT_EQ(load_json(doc("")).materials.size(), 1u);
}

// Plain sphere objects take a fast path (scan_sphere: no DOM per element); anything else in the
// element (here a "comment") sends it through the general reader. Both give the same spheres,
// bit for bit: numbers as nlohmann reads them (integers, -0, exponents, 17 digits), names,
// default names, materials, the default material; and values the fast path leaves to the
// general one (an unknown material, a radius of 0) still fail there with the located error.
TEST(SceneFile, SphereFastPathMatchesTheGeneralReader) {
    const std::vector<std::string> spheres = {
        R"("type": "sphere", "center": [1, -2, 3], "radius": 0.5, "material": "m")",
        R"("center": [-0, 0.0, -0.0], "radius": 2, "type": "sphere")",
        R"("type":"sphere","name":"né","center":[1e3,-2.5E-3,0.30000000000000004],"radius":1e-7)",
        R"("type": "sphere", "name": "ball", "material": "m", "center": [ 123456789012, 7 , 1.5e+2 ], "radius": 3.25)",
        R"("type": "sphere", "center": [1, 2, 3], "radius": 1, "name": "plain")"};
    auto file = [&](bool comment) {
        std::string objects;
        for (const std::string& body : spheres)
            objects += std::string(objects.empty() ? "" : ",\n") + "{" + body + (comment ? R"(, "comment": "x")" : "") + "}";
        return doc(R"("materials": {"m": {"kd": 1}}, "objects": [)" + objects + "]");
    };
    const Scene fast = load_json(file(false), {}, "fast.json");
    const Scene general = load_json(file(true), {}, "general.json");
    ASSERT_EQ(fast.spheres.size(), spheres.size());
    ASSERT_EQ(general.spheres.size(), spheres.size());
    for (size_t i = 0; i < spheres.size(); ++i) {
        SCOPED_TRACE(spheres[i]);
        const Sphere& a = fast.spheres[i];
        const Sphere& b = general.spheres[i];
        EXPECT_EQ(a.name, b.name);
        EXPECT_EQ(a.material, b.material);
        EXPECT_EQ(std::memcmp(&a.center, &b.center, sizeof(a.center)), 0);
        EXPECT_EQ(std::memcmp(&a.radius, &b.radius, sizeof(a.radius)), 0);
    }
    EXPECT_EQ(fast.spheres[1].name, "sphere 1");
    EXPECT_TRUE(std::signbit(fast.spheres[1].center.z));  // -0.0 stays negative, -0 is an integer 0
    EXPECT_FALSE(std::signbit(fast.spheres[1].center.x));
    EXPECT_EQ(fast.spheres[2].name, "n\xC3\xA9");       // an escape: the general path decodes it
    EXPECT_EQ(fast.materials.size(), general.materials.size());
    const Error unknown = error_of(doc(R"("objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1},
      {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "nope"}])"));
    EXPECT_EQ(unknown.location().pointer, "/objects/1/material");
    EXPECT_CONTAINS(std::string(unknown.what()), "unknown material 'nope'");
    const Error zero = error_of(doc(R"("objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 0}])"));
    EXPECT_EQ(zero.location().pointer, "/objects/0/radius");
}

// Plain mesh objects (as the bench's exporter writes them) are read without nlohmann's lexer
// (scan_mesh); the value must be the one nlohmann parses, number types included (an integer
// index stays an integer, -0 an integer 0, -0.0 a negative double), so read_mesh sees the same
// input and makes the same checks. Anything else (another key, a duplicate, an escape, a
// transform that is not a plain matrix, a number out of range) is left to the general parse.
TEST(SceneFile, MeshFastPathParsesAsNlohmannDoes) {
    for (const char* text : {
             R"({"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]})",
             R"({"type":"mesh","positions":[0,0,0,1.5,-0,0,0,1e3,-0.0],"indices":[0,1,2],"material":"m","name":"n"})",
             R"( { "normals" : [ [0, 0, 1], [0, 0, 1], [0, 0, 1] ], "type" : "mesh",
                   "positions" : [ [0.30000000000000004, 2.5E-3, 123456789012], [1, 0, 0], [0, 1, 0] ],
                   "indices" : [ [0, 1, 2] ], "transform" : { "matrix" : [1,0,0,0, 0,1,0,0, 0,0,1,0, 2,3,4,1] } } )",
             R"({"type": "mesh", "positions": [], "indices": []})"}) {
        SCOPED_TRACE(text);
        scene_file::Json fast;
        ASSERT_TRUE(scene_file::scan_mesh(text, fast));
        EXPECT_EQ(fast.dump(), scene_file::Json::parse(text).dump());
    }
    for (const char* text : {
             R"({"type": "mesh", "positions": [[0, 0, 0]], "comment": "x"})",
             R"({"type": "sphere", "positions": [[0, 0, 0]]})",
             R"({"type": "mesh", "positions": [[0, 0, 0]], "positions": [[1, 1, 1]]})",
             R"({"type": "mesh", "name": "a\u00e9", "positions": [[0, 0, 0]]})",
             R"({"type": "mesh", "positions": [[0, 0, 0]], "transform": {"translate": [1, 0, 0]}})",
             R"({"type": "mesh", "positions": [[0, 0, 1e999]]})",
             R"({"type": "mesh", "positions": [[0, 0, 99999999999999999999]]})",
             R"({"type": "mesh", "positions": [[[0, 0, 0]]]})",
             R"({"type": "mesh", "positions": [["0", 0, 0]]})",
             R"({"type": "mesh", "indices": [0, 1, 2]})"}) {
        scene_file::Json fast;
        EXPECT_FALSE(scene_file::scan_mesh(text, fast)) << text;
    }
    // Whole files: the same mesh through the fast path and (with a "comment") the general one.
    auto file = [](bool comment) {
        return doc(std::string(R"("materials": {"m": {"kd": 1}}, "objects": [{"type": "mesh", "material": "m", )") +
                   (comment ? R"("comment": "x", )" : "") +
                   R"("positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.5]], "indices": [0, 1, 2, 1, 3, 2],
                      "transform": {"matrix": [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 1, 2, 3, 1]}}])");
    };
    const Scene fast = load_json(file(false), {}, "fast.json");
    const Scene general = load_json(file(true), {}, "general.json");
    ASSERT_EQ(fast.meshes.size(), 1u);
    ASSERT_EQ(general.meshes.size(), 1u);
    EXPECT_EQ(fast.meshes[0].name, general.meshes[0].name);
    EXPECT_EQ(fast.meshes[0].indices, general.meshes[0].indices);
    ASSERT_EQ(fast.meshes[0].positions.size(), general.meshes[0].positions.size());
    for (size_t k = 0; k < fast.meshes[0].positions.size(); ++k) {
        EXPECT_EQ(fast.meshes[0].positions[k], general.meshes[0].positions[k]);
        EXPECT_EQ(fast.meshes[0].normals[k], general.meshes[0].normals[k]);
    }
    EXPECT_EQ(fast.instances[0].world_from_object(0, 3), 1.0);
    EXPECT_EQ(fast.instances[0].world_from_object(1, 1), 2.0);
    // The fast path's value still meets read_mesh's checks, located in the file.
    const Error bad = error_of(doc(R"("objects": [{"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [0, 1, 7]}])"));
    EXPECT_EQ(bad.location().pointer, "/objects/0/indices/2");
}

TEST(SceneFile, InfinitePlanes) {
    const Scene s = load_json(doc(R"("objects": [
      {"type": "plane"},
      {"type": "plane", "name": "wall", "point": [0, 0, -5], "normal": [0, 0, 2], "u_axis": [1, 0, 1]},
      {"type": "plane", "point": [0, 0, 0], "normal": [1, 0, 0], "transform": {"translate": [0, 0, 3], "rotate": [90, 0, 0, 1]}}])"));
    ASSERT_EQ(s.planes.size(), 3u);
    EXPECT_TRUE(s.meshes.empty());  // infinite planes stay out of the meshes
    const Plane& p = s.planes[0];
    EXPECT_EQ(p.name, "plane 0");
    expect_vec(p.point, {0, 0, 0});
    expect_vec(p.normal, {0, 1, 0});
    expect_vec(p.u_axis, {1, 0, 0});  // deterministic default, perpendicular to the normal
    const Plane& w = s.planes[1];
    expect_vec(w.normal, {0, 0, 1});   // normalized
    expect_vec(w.u_axis, {1, 0, 0});   // projected into the plane, normalized
    expect_vec(w.point, {0, 0, -5});
    const Plane& t = s.planes[2];
    expect_vec(t.normal, {0, 1, 0}, 1e-12);  // +X rotated 90 degrees about +Z
    expect_vec(t.point, {0, 0, 3}, 1e-12);
    EXPECT_NEAR(dot(t.normal, t.u_axis), 0.0, 1e-12);
    EXPECT_NEAR(length(t.u_axis), 1.0, 1e-12);
    // Default u_axis for other normals: unit and perpendicular.
    for (const char* n : {"[0, 0, 1]", "[1, 1, 1]", "[-0.2, 0.9, 0.1]"}) {
        const Scene q = load_json(doc(std::string(R"("objects": [{"type": "plane", "normal": )") + n + "}]"));
        EXPECT_NEAR(dot(q.planes[0].normal, q.planes[0].u_axis), 0.0, 1e-12) << n;
        EXPECT_NEAR(length(q.planes[0].u_axis), 1.0, 1e-12) << n;
    }
}

TEST(SceneFile, CylindersConesAndDiscs) {
    const Scene s = load_json(doc(R"("materials": {"red": {"kd": [1, 0, 0]}}, "objects": [
      {"type": "cylinder", "base": [0, 0, 0], "apex": [0, 2, 0], "radius": 0.5, "material": "red"},
      {"type": "cylinder", "name": "pipe", "base": [1, 0, 0], "apex": [1, 0, 3], "radius": 0.2, "open": true},
      {"type": "cone", "base": [0, 0, 0], "base_radius": 1, "apex": [0, 0, 1], "apex_radius": 0},
      {"type": "disc", "center": [0, 1, 0], "normal": [0, 0, 2], "radius": 2, "inner_radius": 0.5},
      {"type": "cylinder", "base": [0, 0, 0], "apex": [0, 0, 1], "radius": 1, "transform": {"translate": [5, 0, 0], "scale": [2, 1, 1]}}])"));
    ASSERT_EQ(s.quadrics.size(), 5u);
    EXPECT_TRUE(s.meshes.empty());  // analytic, not tessellated
    const Quadric& c = s.quadrics[0];
    EXPECT_EQ(c.kind, QuadricKind::Cylinder);
    EXPECT_EQ(c.name, "cylinder 0");
    EXPECT_TRUE(c.caps);  // closed unless "open"
    EXPECT_DOUBLE_EQ(c.height, 2.0);
    EXPECT_DOUBLE_EQ(c.radius1, 0.5);
    EXPECT_EQ(s.materials[c.material].name, "red");
    expect_vec(c.world_from_object.apply_point({0, 0, 2}), {0, 2, 0}, 1e-12);  // +Z runs base -> apex
    EXPECT_EQ(s.quadrics[1].name, "pipe");
    EXPECT_FALSE(s.quadrics[1].caps);
    EXPECT_EQ(s.quadrics[2].kind, QuadricKind::Cone);
    EXPECT_DOUBLE_EQ(s.quadrics[2].radius0, 1.0);
    EXPECT_DOUBLE_EQ(s.quadrics[2].radius1, 0.0);
    const Quadric& d = s.quadrics[3];
    EXPECT_EQ(d.kind, QuadricKind::Disc);
    EXPECT_DOUBLE_EQ(d.inner_radius, 0.5);
    expect_vec(d.world_from_object.apply_vector({0, 0, 1}), {0, 0, 1}, 1e-12);  // normal, normalised
    // The transform applies after the frame: an elliptic cylinder 4 wide in X at x = 5.
    const Bounds3d b = quadric_bounds(s.quadrics[4]);
    expect_vec(b.lo, {3, -1, 0}, 1e-12);
    expect_vec(b.hi, {7, 1, 1}, 1e-12);
    // Geometry ids: spheres, then quadrics, then planes; world bounds include the quadrics.
    EXPECT_EQ(s.geom_kind(s.quadric_geom_id(0)), GeomKind::Quadric);
    EXPECT_EQ(s.geom_material(s.quadric_geom_id(0)), c.material);
    EXPECT_NEAR(s.world_bounds().hi.x, 7.0, 1e-12);
    const std::string text = describe_scene(s);
    EXPECT_CONTAINS(text, "quadrics=5 ");
    EXPECT_CONTAINS(text, "cylinder[1]: name=\"pipe\" radius0=0.2 radius1=0.2 height=3 caps=no");
    EXPECT_CONTAINS(text, "disc[3]: name=\"disc 0\" radius=2 inner_radius=0.5");
}

TEST(SceneFile, ErrorBadQuadrics) {
    auto error = [](const std::string& objects) { return std::string(error_of(doc("\"objects\": [" + objects + "]")).what()); };
    EXPECT_CONTAINS(error(R"({"type": "cylinder", "base": [0, 0, 0], "apex": [0, 0, 0], "radius": 1})"),
                    "/objects/0/apex: apex is the base point: the cylinder has no length");
    EXPECT_CONTAINS(error(R"({"type": "cylinder", "base": [0, 0, 0], "apex": [0, 1, 0], "radius": 0})"),
                    "/objects/0/radius: expected a number > 0, got 0");
    EXPECT_CONTAINS(error(R"({"type": "cylinder", "base": [0, 0, 0], "apex": [0, 1, 0]})"), "/objects/0: missing key 'radius' in a cylinder");
    EXPECT_CONTAINS(error(R"({"type": "cone", "base": [0, 0, 0], "apex": [0, 1, 0], "base_radius": 0, "apex_radius": 0})"),
                    "base_radius and apex_radius are both 0");
    EXPECT_CONTAINS(error(R"({"type": "cone", "base": [0, 0, 0], "apex": [0, 1, 0], "base_radius": -1, "apex_radius": 0})"),
                    "/objects/0/base_radius: expected a number >= 0, got -1");
    EXPECT_CONTAINS(error(R"({"type": "disc", "center": [0, 0, 0], "radius": 1, "inner_radius": 1})"),
                    "/objects/0/inner_radius: inner_radius (1) must be less than radius (1)");
    EXPECT_CONTAINS(error(R"({"type": "disc", "center": [0, 0, 0], "normal": [0, 0, 0], "radius": 1})"),
                    "/objects/0/normal: expected a direction");
    EXPECT_CONTAINS(error(R"({"type": "cylinder", "base": [0, 0, 0], "apex": [0, 1, 0], "radius": 1, "open": "yes"})"),
                    "/objects/0/open: expected true or false");
    EXPECT_CONTAINS(error(R"({"type": "cylinder", "base": [0, 0, 0], "apex": [0, 1, 0], "radius": 1, "caps": true})"),
                    "/objects/0/caps: unknown key 'caps' in a cylinder");
    EXPECT_CONTAINS(error(R"({"type": "cylinder", "base": [0, 0, 0], "apex": [0, 1, 0], "radius": 1, "transform": {"scale": [1, 0, 1]}})"),
                    "the transform is singular");
    EXPECT_CONTAINS(error(R"({"type": "cylinder", "base": [0, 0, 0], "apex": [0, 1, 0], "radius": 3e38, "transform": {"scale": 10}})"),
                    "beyond the float range");
    EXPECT_CONTAINS(error(R"({"type": "cylindre"})"), "/objects/0/type: expected one of");
}

/// Geometric normal of triangle t in world space.
Vec3d world_face_normal(const Scene& s, const Instance& inst, size_t t) {
    const Mesh& m = s.meshes[inst.mesh];
    Vec3d p[3];
    for (int k = 0; k < 3; ++k) p[k] = inst.world_from_object.apply_point(Vec3d(m.positions[m.indices[t * 3 + size_t(k)]]));
    return cross(p[1] - p[0], p[2] - p[0]);
}

TEST(SceneFile, FinitePlaneIsTwoTrianglesFacingTheNormal) {
    const Scene s = load_json(doc(R"("objects": [
      {"type": "plane", "point": [1, 2, 3], "normal": [0, 0, 1], "u_axis": [1, 0, 0], "size": [4, 2]}])"));
    EXPECT_TRUE(s.planes.empty());
    ASSERT_EQ(s.meshes.size(), 1u);
    ASSERT_EQ(s.instances.size(), 1u);
    const Mesh& m = s.meshes[0];
    EXPECT_EQ(m.triangle_count(), 2u);
    EXPECT_EQ(m.positions.size(), 4u);
    EXPECT_EQ(m.name, "plane 0");
    EXPECT_EQ(s.instances[0].node_name, "plane 0");
    EXPECT_EQ(s.instances[0].node, -1);
    for (size_t t = 0; t < 2; ++t) {
        const Vec3d n = normalize(world_face_normal(s, s.instances[0], t));
        expect_vec(n, {0, 0, 1}, 1e-6);
    }
    for (const Vec3f& n : m.normals) expect_vec(n, Vec3f(0, 0, 1));
    // Centered at `point`, width along u_axis, height along cross(normal, u_axis).
    Bounds3d b;
    for (const Vec3f& p : m.positions) b.extend(Vec3d(p));
    expect_vec(b.lo, {-1, 1, 3}, 1e-6);
    expect_vec(b.hi, {3, 3, 3}, 1e-6);
    // UVs span 0..1, (0, 0) at the top-left corner seen from the front.
    ASSERT_EQ(m.uv0.size(), 4u);
    for (size_t i = 0; i < 4; ++i) {
        const Vec3f& p = m.positions[i];
        EXPECT_FLOAT_EQ(m.uv0[i].x, (p.x + 1.f) / 4.f);
        EXPECT_FLOAT_EQ(m.uv0[i].y, 1.f - (p.y - 1.f) / 2.f);
    }
}

TEST(SceneFile, BoxHasTwelveOutwardTriangles) {
    const Scene s = load_json(doc(R"("objects": [{"type": "box", "name": "crate", "min": [-1, 0, -2], "max": [1, 2, 2]}])"));
    ASSERT_EQ(s.meshes.size(), 1u);
    const Mesh& m = s.meshes[0];
    EXPECT_EQ(m.name, "crate");
    EXPECT_EQ(m.triangle_count(), 12u);
    EXPECT_EQ(m.positions.size(), 24u);
    ASSERT_EQ(m.normals.size(), 24u);
    ASSERT_EQ(m.uv0.size(), 24u);
    const Vec3d center{0, 1, 0};
    int per_axis[3] = {0, 0, 0};
    for (size_t t = 0; t < 12; ++t) {
        const Vec3d fn = normalize(world_face_normal(s, s.instances[0], t));
        Vec3d centroid(0.0);
        for (int k = 0; k < 3; ++k) centroid += Vec3d(m.positions[m.indices[t * 3 + size_t(k)]]) / 3.0;
        EXPECT_GT(dot(fn, centroid - center), 0.0) << "triangle " << t << " faces inward";
        for (int k = 0; k < 3; ++k) expect_vec(Vec3d(m.normals[m.indices[t * 3 + size_t(k)]]), fn, 1e-6);
        for (int a = 0; a < 3; ++a)
            if (std::fabs(fn[a]) > 0.5) ++per_axis[a];
    }
    EXPECT_EQ(per_axis[0], 4);
    EXPECT_EQ(per_axis[1], 4);
    EXPECT_EQ(per_axis[2], 4);
    for (const Vec2f& uv : m.uv0) {
        EXPECT_TRUE(uv.x == 0.f || uv.x == 1.f);
        EXPECT_TRUE(uv.y == 0.f || uv.y == 1.f);
    }
    const Bounds3d b = s.world_bounds();
    expect_vec(b.lo, {-1, 0, -2}, 1e-6);
    expect_vec(b.hi, {1, 2, 2}, 1e-6);
}

TEST(SceneFile, MirroringTransformKeepsBoxFacesOutward) {
    const Scene s = load_json(doc(R"("objects": [{"type": "box", "min": [0, 0, 0], "max": [1, 1, 1],
      "transform": {"scale": [-1, 1, 1]}}])"));
    const Vec3d center{-0.5, 0.5, 0.5};
    const Mesh& m = s.meshes[0];
    for (size_t t = 0; t < 12; ++t) {
        const Vec3d fn = world_face_normal(s, s.instances[0], t);
        Vec3d centroid(0.0);
        for (int k = 0; k < 3; ++k)
            centroid += s.instances[0].world_from_object.apply_point(Vec3d(m.positions[m.indices[t * 3 + size_t(k)]])) / 3.0;
        EXPECT_GT(dot(fn, centroid - center), 0.0) << "triangle " << t;
    }
}

TEST(SceneFile, InlineMeshes) {
    const Scene s = load_json(doc(R"("objects": [
      {"type": "mesh", "name": "quad", "positions": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
       "indices": [[0, 1, 2], [0, 2, 3]], "normals": [[0, 0, 2], [0, 0, 1], [0, 0, 1], [0, 0, 1]],
       "uvs": [[0, 1], [1, 1], [1, 0], [0, 0]], "colors": [[1, 0, 0, 0.5], [0, 1, 0, 1], [0, 0, 1, 1], [1, 1, 1, 1]]},
      {"type": "mesh", "positions": [0, 0, 0, 1, 0, 0, 0, 1, 0], "colors": [1, 0, 0, 0, 1, 0, 0, 0, 1]}])"));
    ASSERT_EQ(s.meshes.size(), 2u);
    const Mesh& q = s.meshes[0];
    EXPECT_EQ(q.name, "quad");
    EXPECT_EQ(q.triangle_count(), 2u);
    EXPECT_EQ(q.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
    expect_vec(q.normals[0], Vec3f(0, 0, 1));  // normalized
    EXPECT_FLOAT_EQ(q.uv0[1].x, 1.f);
    EXPECT_FLOAT_EQ(q.colors[0].w, 0.5f);
    // Flat arrays; no indices = a triangle list; normals generated; RGB colors get alpha 1.
    const Mesh& t = s.meshes[1];
    EXPECT_EQ(t.name, "mesh 1");
    EXPECT_EQ(t.positions.size(), 3u);
    EXPECT_EQ(t.indices, (std::vector<uint32_t>{0, 1, 2}));
    ASSERT_EQ(t.normals.size(), 3u);
    expect_vec(t.normals[0], Vec3f(0, 0, 1));
    ASSERT_EQ(t.colors.size(), 3u);
    EXPECT_FLOAT_EQ(t.colors[1].y, 1.f);
    EXPECT_FLOAT_EQ(t.colors[1].w, 1.f);
    EXPECT_TRUE(t.uv0.empty());
    EXPECT_EQ(s.instances.size(), 2u);
    EXPECT_EQ(s.instances[1].mesh, 1u);
}

TEST(SceneFile, TransformsComposeAsTranslateRotateScale) {
    const Scene s = load_json(doc(R"("objects": [
      {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1], "transform": {"translate": [1, 2, 3], "rotate": [90, 0, 1, 0], "scale": [2, 3, 4]}},
      {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1], "transform": {"rotate": [[90, 0, 0, 1], [90, 1, 0, 0]]}},
      {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1], "transform": {"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 6, 7, 1]}},
      {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1], "transform": {"scale": 2}}])"));
    ASSERT_EQ(s.instances.size(), 4u);
    const Mat4d ry = Mat4d::rotate(0, std::sin(45 * kDeg), 0, std::cos(45 * kDeg));
    expect_mat(s.instances[0].world_from_object, Mat4d::translate({1, 2, 3}) * ry * Mat4d::scale({2, 3, 4}));
    // Rotations in a list apply in order: first about Z, then about X.
    const Mat4d rz = Mat4d::rotate(0, 0, std::sin(45 * kDeg), std::cos(45 * kDeg));
    const Mat4d rx = Mat4d::rotate(std::sin(45 * kDeg), 0, 0, std::cos(45 * kDeg));
    expect_mat(s.instances[1].world_from_object, rx * rz);
    expect_vec(s.instances[1].world_from_object.apply_vector({1, 0, 0}), {0, 0, 1}, 1e-12);
    // Column-major matrix: the translation is elements 12..14.
    expect_mat(s.instances[2].world_from_object, Mat4d::translate({5, 6, 7}));
    expect_mat(s.instances[3].world_from_object, Mat4d::scale({2, 2, 2}));
}

TEST(SceneFile, Lights) {
    const Scene s = load_json(doc(R"("lights": [
      {"type": "point", "name": "bulb", "position": [0, 5, 5], "color": [1, 0.5, 0.25], "intensity": 40,
       "attenuation": "inverse_square", "range": 20},
      {"type": "point", "position": [1, 2, 3], "intensity": 1, "attenuation": [1, 0.05, 0.01]},
      {"type": "spot", "position": [0, 5, 0], "look_at": [0, 0, 0], "inner_angle": 20, "outer_angle": 30, "intensity": 50},
      {"type": "spot", "position": [0, 5, 0], "direction": [0, 0, -2], "attenuation": "none"},
      {"type": "directional", "direction": [-1, -1, -1], "intensity": 2}])"));
    ASSERT_EQ(s.lights.size(), 5u);
    const Light& p = s.lights[0];
    EXPECT_EQ(p.name, "bulb");
    EXPECT_EQ(p.type, LightType::Point);
    expect_vec(p.color, Color(1, 0.5f, 0.25f));
    EXPECT_FLOAT_EQ(p.intensity, 40.f);
    EXPECT_EQ(p.attenuation, Attenuation::InverseSquare);
    EXPECT_FLOAT_EQ(p.range, 20.f);
    expect_vec(p.position, {0, 5, 5});
    EXPECT_FALSE(p.is_default);
    const Light& c = s.lights[1];
    EXPECT_EQ(c.name, "point light 1");
    EXPECT_EQ(c.attenuation, Attenuation::Classic);
    expect_vec(c.classic_c, Vec3f(1, 0.05f, 0.01f));
    const Light& sp = s.lights[2];
    EXPECT_EQ(sp.type, LightType::Spot);
    expect_vec(sp.direction, {0, -1, 0});
    EXPECT_NEAR(sp.inner_cone, 20 * kDeg, 1e-6);
    EXPECT_NEAR(sp.outer_cone, 30 * kDeg, 1e-6);
    EXPECT_EQ(sp.attenuation, Attenuation::InverseSquare);  // default for point and spot
    const Light& s2 = s.lights[3];
    expect_vec(s2.direction, {0, 0, -1});
    EXPECT_EQ(s2.attenuation, Attenuation::None);
    EXPECT_FLOAT_EQ(s2.inner_cone, 0.f);
    EXPECT_NEAR(s2.outer_cone, 45 * kDeg, 1e-6);
    EXPECT_FLOAT_EQ(s2.intensity, 1.f);
    const Light& d = s.lights[4];
    EXPECT_EQ(d.type, LightType::Directional);
    EXPECT_EQ(d.attenuation, Attenuation::None);
    expect_vec(d.direction, normalize(Vec3d(-1, -1, -1)));
    EXPECT_FLOAT_EQ(d.intensity, 2.f);
    EXPECT_EQ(d.name, "directional light 0");
}

TEST(SceneFile, DefaultCameraAndLightLikeGltf) {
    const Scene s = load_json(doc(R"("objects": [{"type": "sphere", "center": [0, 1, 0], "radius": 1}])"));
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_TRUE(s.lights[0].is_default);
    EXPECT_EQ(s.lights[0].type, LightType::Directional);
    ASSERT_EQ(s.cameras.size(), 1u);
    EXPECT_TRUE(s.cameras[0].is_default);
    // The default camera looks at the bounds' centre (the sphere's).
    const Vec3d eye = s.cameras[0].world_from_camera.apply_point({0, 0, 0});
    const Vec3d fwd = s.cameras[0].world_from_camera.apply_vector({0, 0, -1});
    expect_vec(normalize(Vec3d(0, 1, 0) - eye), fwd, 1e-9);
    bool light_warning = false, camera_warning = false;
    for (const std::string& w : s.warnings) {
        light_warning |= contains(w, "added the default light");
        camera_warning |= contains(w, "added a default camera");
    }
    EXPECT_TRUE(light_warning);
    EXPECT_TRUE(camera_warning);
    // Same default light as a glTF file without lights.
    const Scene g = import_gltf(asset("Box/glTF/Box.gltf"));
    ASSERT_EQ(g.lights.size(), 1u);
    expect_vec(s.lights[0].direction, g.lights[0].direction);
    EXPECT_EQ(s.lights[0].intensity, g.lights[0].intensity);
    // The options turn them off.
    ImportOptions o;
    o.add_default_camera = false;
    o.add_default_light = false;
    const Scene n = load_json(doc(""), o);
    EXPECT_TRUE(n.cameras.empty());
    EXPECT_TRUE(n.lights.empty());
    // A scene-file camera counts: no default camera then.
    EXPECT_FALSE(load_json(doc(R"("camera": {"position": [0, 0, 5]})")).cameras[0].is_default);
}

// ---------------------------------------------------------------------------------------------
// Includes

TEST(SceneFile, IncludeComposesTransformsAndRemapsIndices) {
    const std::string box = gltf_dir() + "/Box/glTF/Box.gltf";
    const std::string json = doc(R"("materials": {"m": {"kd": 1}},
      "camera": {"position": [0, 0, 9]},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"},
                  {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1], "material": "m"}],
      "include": [{"file": ")" + box + R"(", "transform": {"translate": [2, 0, 0], "rotate": [90, 0, 1, 0], "scale": 0.5}}])");
    const Scene s = load_json(json);
    const Scene g = import_gltf(box);
    ASSERT_EQ(s.meshes.size(), 1 + g.meshes.size());
    ASSERT_EQ(s.instances.size(), 1 + g.instances.size());
    ASSERT_EQ(s.materials.size(), 1 + g.materials.size());
    const Mat4d xf = Mat4d::translate({2, 0, 0}) * Mat4d::rotate(0, std::sin(45 * kDeg), 0, std::cos(45 * kDeg)) *
                     Mat4d::scale({0.5, 0.5, 0.5});
    for (size_t i = 0; i < g.instances.size(); ++i) {
        const Instance& in = s.instances[1 + i];
        EXPECT_EQ(in.mesh, 1 + g.instances[i].mesh);
        expect_mat(in.world_from_object, xf * g.instances[i].world_from_object);
        EXPECT_EQ(s.meshes[in.mesh].material, 1 + g.meshes[g.instances[i].mesh].material);
    }
    EXPECT_EQ(s.materials[1].name, "Red");
    EXPECT_EQ(s.materials[1].model, MaterialModel::GltfPbr);
    // The scene-file camera stays first; no default light added by the include, one by the file.
    EXPECT_FALSE(s.cameras[0].is_default);
    EXPECT_EQ(s.cameras.size(), 1u);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_TRUE(s.lights[0].is_default);
}

// An include poses its glTF file at the render's time plus its time_offset, under its own animation
// choice: the same instances as importing the file at that time; an unknown animation is an error
// located at the include.
TEST(SceneFile, IncludeAnimationAndTimeOffset) {
    const std::string tri = gltf_dir() + "/AnimatedTriangle/glTF/AnimatedTriangle.gltf";
    ImportOptions at;
    at.time = 0.5;
    const std::string json = doc(R"("camera": {"position": [0, 0, 9]},
      "include": [{"file": ")" + tri + R"(", "time_offset": 0.25, "animation": "0"},
                  {"file": ")" + tri + R"(", "time_offset": -2}])");
    const Scene s = load_json(json, at);
    ImportOptions later, first;
    later.time = 0.75;
    const Scene g = import_gltf(tri, later);
    const Scene g0 = import_gltf(tri, first);
    ASSERT_EQ(s.instances.size(), 2 * g.instances.size());
    expect_mat(s.instances[0].world_from_object, g.instances[0].world_from_object);
    expect_mat(s.instances[1].world_from_object, g0.instances[0].world_from_object);  // before the first key
    EXPECT_NE(g.instances[0].world_from_object, g0.instances[0].world_from_object);
    ASSERT_EQ(s.animations.size(), 2u);
    EXPECT_EQ(s.time, 0.5);
    const Error e = error_of(doc(R"("include": [{"file": ")" + tri + R"(", "animation": "walk"}])"));
    EXPECT_NE(std::string(e.what()).find("no animation 'walk'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("included from"), std::string::npos) << e.what();
}

TEST(SceneFile, IncludeTransformsLightsAndCameras) {
    const std::string lamp = gltf_dir() + "/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf";
    const std::string cams = gltf_dir() + "/Cameras/glTF/Cameras.gltf";
    const std::string json = doc(R"("camera": {"name": "mine", "position": [0, 0, 9]},
      "lights": [{"type": "point", "name": "own", "position": [0, 9, 0]}],
      "include": [{"file": ")" + lamp + R"(", "transform": {"translate": [10, 0, 0], "rotate": [90, 0, 1, 0]}},
                  {"file": ")" + cams + R"(", "transform": {"translate": [0, 0, -1]}}])");
    const Scene s = load_json(json, no_textures());
    const Scene l = import_gltf(lamp, no_textures());
    ImportOptions no_defaults = no_textures();
    no_defaults.add_default_light = false;
    const Scene c = import_gltf(cams, no_defaults);
    const Mat4d xf = Mat4d::translate({10, 0, 0}) * Mat4d::rotate(0, std::sin(45 * kDeg), 0, std::cos(45 * kDeg));
    ASSERT_EQ(s.lights.size(), 1 + l.lights.size());
    EXPECT_EQ(s.lights[0].name, "own");
    for (size_t i = 0; i < l.lights.size(); ++i) {
        const Light& a = s.lights[1 + i];
        EXPECT_EQ(a.name, l.lights[i].name);
        expect_vec(a.position, xf.apply_point(l.lights[i].position), 1e-9);
        if (l.lights[i].type != LightType::Point) expect_vec(a.direction, normalize(xf.apply_vector(l.lights[i].direction)), 1e-9);
    }
    // Cameras: the file's first, then the included ones with the transform premultiplied.
    ASSERT_EQ(s.cameras.size(), 1 + c.cameras.size());
    EXPECT_EQ(s.cameras[0].name, "mine");
    for (size_t i = 0; i < c.cameras.size(); ++i)
        expect_mat(s.cameras[1 + i].world_from_camera, Mat4d::translate({0, 0, -1}) * c.cameras[i].world_from_camera);
    // lights/cameras false leave them out.
    const Scene off = load_json(doc(R"("include": [{"file": ")" + cams + R"(", "cameras": false, "lights": false}])"),
                                no_textures());
    EXPECT_EQ(off.cameras.size(), 1u);
    EXPECT_TRUE(off.cameras[0].is_default);
}

TEST(SceneFile, IncludeBundledDuckWithMaterialOverride) {
    const std::string json = doc(R"("materials": {"mirror": {"kd": 0.05, "ks": 0.8}},
      "include": [{"file": "../gltf/Duck/glTF-Binary/Duck.glb", "transform": {"scale": 0.01}, "scene": 0,
                   "materials": {"blinn3-fx": "mirror"}}])");
    // Written next to assets/gltf to use a relative path with "..".
    const std::filesystem::path dir = scratch_dir() / "scenes";
    std::filesystem::create_directories(dir);
    std::filesystem::path gltf = dir.parent_path() / "gltf";
    std::error_code ec;
    std::filesystem::create_directory_symlink(gltf_dir(), gltf, ec);
    const std::string path = write_file("scenes/duck.json", json);
    const Scene s = load_scene(path, no_textures());  // dispatch on .json
    const Scene d = import_gltf(gltf_dir() + "/Duck/glTF-Binary/Duck.glb", no_textures());
    ASSERT_EQ(s.meshes.size(), d.meshes.size());
    for (const Mesh& m : s.meshes) EXPECT_EQ(m.material, 0u) << m.name;  // every duck mesh uses "mirror"
    EXPECT_EQ(s.materials[0].name, "mirror");
    EXPECT_EQ(s.textures.size(), d.textures.size());
    EXPECT_EQ(s.cameras.size(), d.cameras.size());  // the Duck's own camera
    EXPECT_FALSE(s.cameras[0].is_default);
    EXPECT_EQ(s.instanced_triangle_count(), d.instanced_triangle_count());
    const Bounds3d a = s.world_bounds(), b = d.world_bounds();
    expect_vec(a.lo, b.lo * 0.01, 1e-4);
    expect_vec(a.hi, b.hi * 0.01, 1e-4);
}

TEST(SceneFile, IncludeMirroringTransformFlipsWinding) {
    const std::string box = gltf_dir() + "/Box/glTF/Box.gltf";
    const Scene s = load_json(doc(R"("include": [{"file": ")" + box + R"(", "transform": {"scale": [-1, 1, 1]}}])"));
    const Scene g = import_gltf(box);
    const Mesh& a = s.meshes[0];
    const Mesh& b = g.meshes[0];
    ASSERT_EQ(a.indices.size(), b.indices.size());
    EXPECT_EQ(a.indices[1], b.indices[2]);
    EXPECT_EQ(a.indices[2], b.indices[1]);
}

TEST(SceneFile, BundledFixtures) {
    const Scene w = import_scene_file(fixture("whitted1980.json"));
    EXPECT_EQ(w.spheres.size(), 2u);
    EXPECT_EQ(w.planes.size(), 1u);
    EXPECT_EQ(w.lights.size(), 2u);
    EXPECT_EQ(w.cameras.size(), 1u);
    EXPECT_EQ(w.textures[0].kind, TextureKind::Checker);
    EXPECT_EQ(w.settings.output, "whitted1980.png");
    EXPECT_TRUE(w.warnings.empty()) << w.warnings[0];

    const Scene q = import_scene_file(std::string(WHITTED_ASSETS_DIR) + "/scenes/quadrics.json");
    EXPECT_EQ(q.quadrics.size(), 8u);
    EXPECT_TRUE(q.warnings.empty()) << q.warnings[0];

    const Scene e = import_scene_file(fixture("every_key.json"));
    EXPECT_EQ(e.cameras.size(), 2u);  // "cameras": false on the Duck
    EXPECT_EQ(e.settings.camera, 1);
    EXPECT_EQ(e.spheres.size(), 1u);
    EXPECT_EQ(e.planes.size(), 1u);
    EXPECT_EQ(e.lights.size(), 5u);  // the Duck has none
    EXPECT_TRUE(e.warnings.empty()) << e.warnings[0];
    EXPECT_EQ(e.textures[0].name, "logo");
    EXPECT_FALSE(e.textures[0].levels.empty());
    EXPECT_EQ(e.textures[0].wrap_s, WrapMode::ClampToEdge);
    EXPECT_EQ(e.textures[1].kind, TextureKind::Checker);
}

TEST(SceneFile, InfoReportListsScenePrimitives) {
    const std::string text = describe_scene(import_scene_file(fixture("whitted1980.json")));
    EXPECT_CONTAINS(text, "spheres=2 ");
    EXPECT_CONTAINS(text, "planes=1 ");
    EXPECT_CONTAINS(text, "sphere[0]: name=\"glass ball\" center=(0.3, 1, 1.5) radius=0.7 material=0");
    EXPECT_CONTAINS(text, "plane[0]: name=\"floor\" point=(0, 0, 0) normal=(0, 1, 0) u_axis=(1, 0, 0) material=2");
    EXPECT_CONTAINS(text, "texture[0]: name=\"floor_checker\" kind=checker color_a=(1, 0, 0) color_b=(1, 1, 0) size=0.5 space=world");
    EXPECT_CONTAINS(text, "material[2] textures: classic_color=tex0(uv0)");
    EXPECT_CONTAINS(text, "material[0] whitted: kd=(0, 0, 0) ka=(0, 0, 0) ks=(0.1, 0.1, 0.1) n=200 kr=(0.1, 0.1, 0.1) kt=(0.9, 0.9, 0.9) ior=1.5");
    EXPECT_CONTAINS(text, "settings: width=320 height=240 aa=adaptive aa_threshold=0.1 aa_depth=3 max_depth=5");
    EXPECT_CONTAINS(text, "output=\"whitted1980.png\" view=\"Standard\" display=\"sRGB\" camera=0");
    EXPECT_CONTAINS(text, "attenuation=classic");
}

// ---------------------------------------------------------------------------------------------
// Errors: file, JSON pointer, line:column, what was expected

TEST(SceneFile, ErrorBadTypeNamesPointerLineColumnAndExpectation) {
    const std::string json = "{\"version\": 1,\n \"objects\": [\n  {\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": \"abc\"}\n ]\n}";
    const Error e = error_of(json);
    EXPECT_EQ(e.location().pointer, "/objects/0/radius");
    EXPECT_EQ(e.location().line, 3);
    EXPECT_EQ(e.location().column, 53);
    EXPECT_CONTAINS(e.location().file, "bad.json");
    EXPECT_CONTAINS(std::string(e.what()), "bad.json:3:53: /objects/0/radius: expected a number > 0, got \"abc\"");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("ambient": "bright")")).what()),
                    "/ambient: expected a color: a number >= 0 (gray) or an array of 3 numbers >= 0 (linear RGB), got \"bright\"");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "sphere", "center": [0, 0], "radius": 1}])")).what()),
                    "/objects/0/center: expected an array of 3 numbers, got an array of 2 elements");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("render": {"width": 10.5})")).what()),
                    "/render/width: expected an integer in [1, 32768], got 10.5");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("render": {"fresnel": 1})")).what()), "/render/fresnel: expected true or false, got 1");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": {})")).what()), "/objects: expected an array of objects, got an empty object");
    EXPECT_CONTAINS(std::string(error_of("[1, 2]").what()), "expected an object (the scene file), got an array of 2 elements");
}

TEST(SceneFile, ErrorUnknownKeyWithSuggestion) {
    const std::string json = "{\"version\": 1, \"objects\": [\n{\"type\": \"sphere\", \"center\": [0,0,0], \"radus\": 1}]}";
    const Error e = error_of(json);
    EXPECT_EQ(e.location().pointer, "/objects/0/radus");
    EXPECT_EQ(e.location().line, 2);
    EXPECT_EQ(e.location().column, 39);  // at the key
    EXPECT_CONTAINS(std::string(e.what()), "unknown key 'radus' in a sphere (did you mean 'radius'?)");
    // Everywhere: top level, render, materials, lights, transforms, textures, includes.
    EXPECT_CONTAINS(std::string(error_of(doc(R"("light": [])")).what()), "unknown key 'light' in the scene file (did you mean 'lights'?)");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("render": {"widht": 3})")).what()), "(did you mean 'width'?)");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("materials": {"m": {"Kd": 1}})")).what()), "unknown key 'Kd' in a material (did you mean 'kd'?)");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("lights": [{"type": "directional", "direction": [0,-1,0], "range": 3}])")).what()),
                    "unknown key 'range' in a directional light");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "box", "min": [0,0,0], "max": [1,1,1], "transform": {"rotation": [90, 0, 1, 0]}}])")).what()),
                    "(did you mean 'rotate'?)");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("textures": {"c": {"type": "checker", "colours": [0, 1]}})")).what()),
                    "(did you mean 'colors'?)");
    // No close match: the accepted keys are listed.
    EXPECT_CONTAINS(std::string(error_of(doc(R"("camera": {"position": [0,0,0], "zoom": 2})")).what()),
                    "unknown key 'zoom' in a perspective camera (expected one of: type, name, position, look_at");
    // Enumerations suggest too.
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "spere"}])")).what()),
                    "/objects/0/type: expected one of \"sphere\", \"cylinder\", \"cone\", \"disc\", \"plane\", \"box\", \"mesh\", got \"spere\" (did you mean 'sphere'?)");
}

TEST(SceneFile, ErrorMissingKey) {
    const Error e = error_of(doc(R"("objects": [{"type": "sphere", "center": [0, 0, 0]}])"));
    EXPECT_EQ(e.location().pointer, "/objects/0");
    EXPECT_CONTAINS(std::string(e.what()), "missing key 'radius' in a sphere (expected a number > 0)");
    EXPECT_CONTAINS(std::string(error_of("{}").what()), "missing key 'version' in the scene file");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("lights": [{"type": "spot", "position": [0, 0, 0]}])")).what()),
                    "missing key 'direction' or 'look_at' in a spot light");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("include": [{"transform": {}}])")).what()), "missing key 'file' in an include");
}

TEST(SceneFile, ErrorMissingFiles) {
    EXPECT_CONTAINS(error_text([] { import_scene_file((scratch_dir() / "nope.json").string()); }), "nope.json: cannot open file");
    const Error inc = error_of(doc(R"("include": [{"file": "missing/thing.glb"}])"));
    EXPECT_EQ(inc.location().pointer, "/include/0/file");
    EXPECT_CONTAINS(std::string(inc.what()), "included file 'missing/thing.glb' not found (looked for '");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("textures": {"t": {"type": "image", "file": "none.png"}})")).what()),
                    "/textures/t/file: image file 'none.png' not found");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("include": [{"file": "other.json"}])")).what()),
                    "'other.json': only glTF files (.gltf, .glb) can be included");
    // A broken image file: OIIO's reason.
    write_file("broken.png", "not a png");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("textures": {"t": {"type": "image", "file": "broken.png"}})")).what()),
                    "/textures/t/file: cannot read image");
}

TEST(SceneFile, ErrorBadNumbers) {
    // NaN is not JSON: a syntax error at its position.
    const Error nan = error_of("{\"version\": 1,\n\"ambient\": NaN}");
    EXPECT_EQ(nan.location().line, 2);
    EXPECT_EQ(nan.location().column, 12);
    EXPECT_CONTAINS(std::string(nan.what()), "invalid JSON");
    // Out of the double range.
    const Error big = error_of("{\"version\": 1,\n \"ambient\": 1e999}");
    EXPECT_EQ(big.location().line, 2);
    EXPECT_EQ(big.location().column, 13);
    EXPECT_CONTAINS(std::string(big.what()), "1e999");
    // Beyond what a float holds (the renderer's precision).
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1e300}])")).what()),
                    "/objects/0/radius: expected a number > 0 within the float range (|x| <= 3.4e38), got 1e+300");
    // Out of the accepted range.
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "sphere", "center": [0, 0, 0], "radius": -1}])")).what()),
                    "/objects/0/radius: expected a number > 0, got -1");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("materials": {"m": {"n": 0}})")).what()), "/materials/m/n: expected a number > 0, got 0");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("materials": {"m": {"kd": [1, -0.5, 0]}})")).what()),
                    "/materials/m/kd/1: expected a number >= 0, got -0.5");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("materials": {"m": {"ior": 0}})")).what()), "/materials/m/ior: expected a number > 0");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("materials": {"m": {"ks": "shiny"}})")).what()), "only kd/color and ka take a texture");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("camera": {"position": [0, 0, 0], "fov": 180})")).what()),
                    "/camera/fov: expected a number in (0, 180), got 180");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("render": {"spp": 10})")).what()), "/render/spp: expected a square number");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("render": {"aa_depth": 9})")).what()), "/render/aa_depth: expected an integer in [0, 8], got 9");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("lights": [{"type": "point", "position": [0,0,0], "attenuation": [0, 0, 0]}])")).what()),
                    "at least one of c1, c2, c3 must be > 0");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("lights": [{"type": "spot", "position": [0,0,0], "direction": [0,-1,0], "inner_angle": 40, "outer_angle": 30}])")).what()),
                    "inner_angle (40) must not exceed outer_angle (30)");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("lights": [{"type": "directional", "direction": [0, 0, 0]}])")).what()),
                    "/lights/0/direction: expected a direction (a non-zero vector)");
}

TEST(SceneFile, ErrorInvalidJsonLineColumn) {
    const Error e = error_of("{\n  \"version\": 1,\n  \"objects\": [1, 2,,]\n}");
    EXPECT_EQ(e.location().line, 3);
    EXPECT_EQ(e.location().column, 20);
    EXPECT_EQ(e.location().pointer, "");
    EXPECT_CONTAINS(std::string(e.what()), "bad.json:3:20: invalid JSON: syntax error while parsing value - unexpected ','");
    // Columns count characters, not bytes.
    const Error u = error_of("{\"version\": 1, \"materials\": {\"\xC3\xA9t\xC3\xA9\": {\"kd\": x}}}");
    EXPECT_EQ(u.location().line, 1);
    EXPECT_EQ(u.location().column, 44);
    EXPECT_CONTAINS(std::string(error_of("").what()), "empty scene file");
    EXPECT_CONTAINS(std::string(error_of("{\"version\": 1} trailing").what()), "invalid JSON");
    EXPECT_CONTAINS(std::string(error_of("\xEF\xBB\xBF{\"version\": 1}").what()), "byte order mark");
    // A duplicate key is an error at the second occurrence.
    const Error dup = error_of("{\"version\": 1,\n \"objects\": [{\"type\": \"sphere\", \"radius\": 1,\n \"radius\": 2}]}");
    EXPECT_EQ(dup.location().pointer, "/objects/0/radius");
    EXPECT_EQ(dup.location().line, 3);
    EXPECT_EQ(dup.location().column, 2);
    EXPECT_CONTAINS(std::string(dup.what()), "duplicate key 'radius'");
}

TEST(SceneFile, ErrorVersion) {
    EXPECT_CONTAINS(std::string(error_of(R"({"version": 2})").what()), "/version: unsupported scene file version 2 (this whitted reads version 1)");
    EXPECT_CONTAINS(std::string(error_of(R"({"version": "1"})").what()), "unsupported scene file version \"1\"");
}

TEST(SceneFile, ErrorUnknownNames) {
    const Error m = error_of(doc(R"("materials": {"glass": {}, "mirror": {}}, "objects": [{"type": "sphere", "center": [0,0,0], "radius": 1, "material": "glas"}])"));
    EXPECT_EQ(m.location().pointer, "/objects/0/material");
    EXPECT_CONTAINS(std::string(m.what()), "unknown material 'glas' (did you mean 'glass'?)");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "sphere", "center": [0,0,0], "radius": 1, "material": "x"}])")).what()),
                    "unknown material 'x': the file defines no materials");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("textures": {"floor_checker": {"type": "checker"}}, "materials": {"m": {"kd": "floor_chekcer"}})")).what()),
                    "/materials/m/kd: unknown texture 'floor_chekcer' (did you mean 'floor_checker'?)");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("materials": {"m": {"kd": "red"}})")).what()),
                    "unknown texture 'red': the file defines no textures");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("textures": {"a": {"type": "checker"}, "b": {"type": "checker"}}, "materials": {"m": {"kd": "a", "ka": "b"}})")).what()),
                    "/materials/m/ka: 'ka' names texture 'b' but 'kd' names 'a': a material has one color texture");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("materials": {"m": {"kd": 1, "color": 1}})")).what()), "'color' is another name for 'kd'");
}

TEST(SceneFile, ErrorIncludeMaterialOverrides) {
    const std::string duck = gltf_dir() + "/Duck/glTF-Binary/Duck.glb";
    const Error e = error_of(doc(R"("materials": {"mirror": {}}, "include": [{"file": ")" + duck +
                                 R"(", "materials": {"blinn3_fx": "mirror"}}])"),
                             no_textures());
    EXPECT_EQ(e.location().pointer, "/include/0/materials/blinn3_fx");
    EXPECT_CONTAINS(std::string(e.what()),
                    "has no material named 'blinn3_fx' (to be replaced by 'mirror') (did you mean 'blinn3-fx'?)");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("materials": {"mirror": {}}, "include": [{"file": ")" + duck +
                                             R"(", "materials": {"blinn3-fx": "miror"}}])"),
                                         no_textures())
                                    .what()),
                    "/include/0/materials/blinn3-fx: unknown material 'miror' (did you mean 'mirror'?)");
}

TEST(SceneFile, ErrorInsideIncludedGltfSaysWhereItWasIncluded) {
    write_file("broken.gltf", R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [5]}]})");
    const Error e = error_of(doc(R"("include": [{"file": "broken.gltf"}])"));
    EXPECT_CONTAINS(e.location().file, "broken.gltf");
    EXPECT_CONTAINS(std::string(e.what()), "(included from ");
    EXPECT_CONTAINS(std::string(e.what()), "bad.json:1:");
    EXPECT_CONTAINS(std::string(e.what()), "/include/0/file)");
    // A scene index the file does not have.
    const Error sc = error_of(doc(R"("include": [{"file": ")" + gltf_dir() + R"(/Box/glTF/Box.gltf", "scene": 3}])"));
    EXPECT_CONTAINS(std::string(sc.what()), "scene 3 requested but the file has 1 scene(s)");
}

TEST(SceneFile, ErrorsOfGeometryAndTransforms) {
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "mesh", "positions": [[0,0,0],[1,0,0],[0,1,0]], "indices": [0, 1, 3]}])")).what()),
                    "/objects/0/indices/2: expected a vertex index in [0, 2], got 3");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "mesh", "positions": [[0,0,0],[1,0,0],[0,1,0]], "indices": [0, 1]}])")).what()),
                    "the index count must be a multiple of 3");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "mesh", "positions": [0,0,0,1,0]}])")).what()),
                    "a flat array of positions needs a multiple of 3 numbers, got 5");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "mesh", "positions": [[0,0,0],[1,0,0],[0,1,0]], "normals": [[0,0,1]]}])")).what()),
                    "1 normals given for 3 positions");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "mesh", "positions": [[0,0,0],[1,0,0],[0,1,0]], "normals": [[0,0,1],[0,0,0],[0,0,1]]}])")).what()),
                    "/objects/0/normals/1: a normal of zero length");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "box", "min": [0,0,0], "max": [1,0,1]}])")).what()),
                    "/objects/0/max/1: max (0) must be greater than min (0)");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "plane", "normal": [0,1,0], "u_axis": [0,2,0]}])")).what()),
                    "u_axis is parallel to the normal");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "box", "min": [0,0,0], "max": [1,1,1], "transform": {"scale": 0}}])")).what()),
                    "/objects/0/transform: the transform is singular");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "box", "min": [0,0,0], "max": [1,1,1], "transform": {"matrix": [1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1], "scale": 2}}])")).what()),
                    "'scale' cannot be combined with 'matrix'");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "box", "min": [0,0,0], "max": [1,1,1], "transform": {"rotate": [90, 0, 0, 0]}}])")).what()),
                    "the rotation axis is (0, 0, 0)");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("camera": {"position": [0, 0, 0], "look_at": [0, 5, 0]})")).what()),
                    "the up vector is parallel to the view direction");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("camera": {"position": [0, 0, 0]}, "render": {"camera": 1})")).what()),
                    "/render/camera: camera 1 requested but the scene has 1 camera(s)");
    EXPECT_CONTAINS(std::string(error_of(doc(R"("objects": [{"type": "sphere", "center": [0,0,0], "radius": 1, "transform": {}}])")).what()),
                    "unknown key 'transform' in a sphere");
}

TEST(SceneFile, HostileInputIsRefusedNotCrashed) {
    // Deep nesting.
    std::string deep = "{\"version\": 1, \"comment\": ";
    for (int i = 0; i < 100000; ++i) deep += '[';
    EXPECT_CONTAINS(std::string(error_of(deep).what()), "nested deeper than 64 levels");
    // A mesh larger than the memory limit is refused before it is allocated.
    std::string big = doc(R"("objects": [{"type": "mesh", "positions": [)");
    big.resize(big.size() - 1);  // drop the closing brace of doc()
    for (int i = 0; i < 200000; ++i) big += i ? ",0,0,0" : "0,0,0";  // 200000 vertices, 1.2 MB of text
    big += "]}]}";
    ImportOptions small;
    small.max_memory = size_t(24) << 20;  // the text may be parsed (< 1/16), the mesh does not fit as well
    EXPECT_CONTAINS(std::string(error_of(big, small).what()), "memory limit");
    // A file too large for the limit is refused before parsing.
    ImportOptions tiny;
    tiny.max_memory = 1000;
    EXPECT_CONTAINS(std::string(error_of(doc(R"("comment": ")" + std::string(200, 'x') + "\""), tiny).what()),
                    "too large for the memory limit");
    // Garbage bytes.
    EXPECT_CONTAINS(std::string(error_of(std::string("\x00\xff\x01{", 4)).what()), "invalid JSON");
}

TEST(SceneFile, LoaderDispatchesJson) {
    const std::string path = write_file("Dispatch.JSON", doc(R"("objects": [{"type": "sphere", "center": [0,0,0], "radius": 1}])"));
    EXPECT_EQ(load_scene(path).spheres.size(), 1u);
    EXPECT_CONTAINS(error_text([] { load_scene((scratch_dir() / "x.obj").string()); }), "(supported: .gltf, .glb, .json)");
}

}  // namespace
}  // namespace whitted::test
