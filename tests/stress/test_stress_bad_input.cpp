// Bad numbers in input (docs/numerical-stability.md, section 6). Files: NaN / infinite values are
// rejected with a located error; denormals are flushed and zero-area triangles kept but reported,
// each kind with one warning and a count. Scenes built in code (which bypass the importers): NaN /
// infinite positions, normals and UVs, zero-area and needle triangles, zero-length normals,
// denormal coordinates, a camera inside geometry, znear 0, a light on the surface; every backend
// renders them without a NaN or infinite pixel. (The glTF importer's own NaN checks are
// unit-tested in tests/unit/test_gltf_importer.cpp; they are not repeated here.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "benchmarks/stability_probes.h"
#include "importers/scene_loader.h"
#include "scene/scene_builder.h"
#include "tests/support/test_importer_util.h"

namespace whitted::stress {
namespace {

using namespace whitted::test;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kDenormal = 1e-40f;

bool has_warning(const Scene& s, const std::string& text) {
    for (const std::string& w : s.warnings)
        if (w.find(text) != std::string::npos) return true;
    return false;
}

// ---- files ----------------------------------------------------------------------------------

std::string scene_file(const std::string& objects) {
    return R"({"version": 1, "camera": {"type": "perspective", "position": [0, 0, 5], "look_at": [0, 0, 0]},
               "materials": {"m": {"kd": 0.5}}, "objects": [)" +
           objects + "]}";
}

TEST(StressBadInput, SceneFileDenormalsAreFlushedWithOneWarning) {
    const Scene s = load_scene(write_file("denormal.json", scene_file(R"(
        {"type": "mesh", "positions": [[0, 0, 1e-40], [1, 0, -1e-41], [0, 1, 0]], "material": "m"})")));
    ASSERT_EQ(s.meshes.size(), 1u);
    for (const Vec3f& p : s.meshes[0].positions) EXPECT_EQ(p.z, 0.f);
    EXPECT_TRUE(has_warning(s, "denormal value(s) (|x| < 1.18e-38) flushed to 0")) << (s.warnings.empty() ? "" : s.warnings[0]);
}

TEST(StressBadInput, SceneFileZeroAreaTrianglesAreCountedInOneWarning) {
    const Scene s = load_scene(write_file("zero_area.json", scene_file(R"(
        {"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 2, 2], [2, 2, 2], [3, 3, 3],
                                       [5, 0, 0], [6, 0, 0], [7, 0, 0]], "material": "m"})")));
    EXPECT_TRUE(has_warning(s, "2 zero-area triangle(s)"));
    EXPECT_EQ(s.meshes[0].triangle_count(), 3u);  // kept: primitive ids unchanged
}

TEST(StressBadInput, SceneFileOutOfRangeNumbersAreLocatedErrors) {
    // 1e39 is a valid JSON number but not a float: positions, UVs and colors say where.
    EXPECT_NE(error_text([] {
                  load_scene(write_file("uv_inf.json", scene_file(R"(
        {"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "uvs": [[0, 0], [1e39, 0], [0, 1]], "material": "m"})")));
              }).find("/objects/0/uvs/1"),
              std::string::npos);
    EXPECT_NE(error_text([] {
                  load_scene(write_file("color_inf.json", scene_file(R"(
        {"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "colors": [[0, 0, 0], [1, 0, 0], [0, -1e39, 1]], "material": "m"})")));
              }).find("/objects/0/colors/2"),
              std::string::npos);
    EXPECT_NE(error_text([] {
                  load_scene(write_file("pos_inf.json", scene_file(R"(
        {"type": "mesh", "positions": [[0, 0, 0], [1e39, 0, 0], [0, 1, 0]], "material": "m"})")));
              }).find("/objects/0/positions/1"),
              std::string::npos);
    EXPECT_NE(error_text([] {
                  load_scene(write_file("normal0.json", scene_file(R"(
        {"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "normals": [[0, 0, 1], [0, 0, 0], [0, 0, 1]], "material": "m"})")));
              }).find("/objects/0/normals/1"),
              std::string::npos);
}

TEST(StressBadInput, GltfDenormalAndZeroAreaAreReported) {
    Bytes b;
    b.put<float>({0, 0, 0, 1, 0, kDenormal, 1, 1, 0, 1, 1, 0});  // vertex 3 = vertex 2: triangle 2 has zero area
    b.put<uint16_t>({0, 1, 2, 1, 2, 3});
    const char* json = R"({
      "asset": {"version": "2.0"},
      "buffers": [{"uri": "$BUFFER", "byteLength": $LENGTH}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
                    {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
      "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})";
    std::string text = json;
    const std::string uri = data_uri(b.data);
    text.replace(text.find("$BUFFER"), 7, uri);
    text.replace(text.find("$LENGTH"), 7, std::to_string(b.size()));
    const Scene s = load_scene(write_file("bad_numbers.gltf", text));
    EXPECT_EQ(s.meshes[0].positions[1].z, 0.f);
    EXPECT_TRUE(has_warning(s, "denormal value(s) (|x| < 1.18e-38) flushed to 0"));
    EXPECT_TRUE(has_warning(s, "1 zero-area triangle(s)"));
}

// ---- scenes built in code -------------------------------------------------------------------

/// A floor, a box, a sphere, a light and a camera, then `spoil` damages it.
template <typename Spoil>
Scene damaged_scene(Spoil&& spoil) {
    Scene s;
    WhittedCoeffs c;
    c.kd = c.ka = Color(0.6f);
    c.ks = Color(0.3f);
    c.n = 20.f;
    c.kr = Color(0.2f);
    const uint32_t m = add_classic_material(s, c, "diffuse");
    WhittedCoeffs g;
    g.kt = Color(0.8f);
    g.kr = Color(0.1f);
    g.ior = 1.5f;
    g.thin = false;
    const uint32_t glass = add_classic_material(s, g, "glass");
    add_mesh(s, make_quad({-5, 0, -5}, {-5, 0, 5}, {5, 0, 5}, {5, 0, -5}, m));
    add_mesh(s, make_box({-1, 0, -1}, {0, 1, 0}, glass));
    Sphere sp;
    sp.center = {1, 0.5, 0.5};
    sp.radius = 0.5;
    sp.material = m;
    s.spheres.push_back(sp);
    s.lights.push_back(point_light({2, 4, 3}, 20.f));
    s.cameras.push_back(make_camera(CameraType::Perspective, {0, 2, 5}, {0, -0.3, -1}, {0, 1, 0}, 0.8));
    spoil(s);
    return s;
}

/// Renders with every backend (and Embree ROBUST); no value of the image may be NaN / infinite.
void expect_finite_renders(const Scene& s, const std::string& what) {
    for (const char* accel : {"embree", "bvh", "grid", "octree", "kdop"})
        for (bool robust : {false, true}) {
            if (robust && std::string(accel) != "embree") continue;
            RenderSettings rs;
            rs.width = 40;
            rs.height = 30;
            rs.accel = accel;
            rs.robust = robust;
            rs.aovs.normal = rs.aovs.albedo = rs.aovs.depth = true;
            RenderStats stats;
            Film f = Renderer(s, rs).render(&stats);
            EXPECT_EQ(f.nonfinite_values(), 0u) << what << " " << accel << (robust ? " robust" : "");
        }
}

TEST(StressBadInput, NonFiniteVerticesNormalsAndUvs) {
    for (float bad : {kNaN, kInf, -kInf}) {
        expect_finite_renders(damaged_scene([&](Scene& s) { s.meshes[1].positions[3].y = bad; }), "position");
        expect_finite_renders(damaged_scene([&](Scene& s) {
                                  for (Vec3f& n : s.meshes[1].normals) n.x = bad;
                              }),
                              "normals");
        expect_finite_renders(damaged_scene([&](Scene& s) {
                                  // UVs feeding a UV-space checker on the floor.
                                  Texture t;
                                  t.kind = TextureKind::Checker;
                                  t.checker.size = 0.25f;
                                  s.textures.push_back(t);
                                  s.materials[0].classic_color_texture.texture = 0;
                                  s.meshes[0].uv0 = {{0, 0}, {bad, 0}, {1, 1}, {0, 1}};
                              }),
                              "uvs");
    }
}

TEST(StressBadInput, DegenerateGeometry) {
    expect_finite_renders(damaged_scene([](Scene& s) {
                              // Zero-area (collinear and coincident) and needle triangles in view.
                              Mesh m;
                              m.positions = {{-0.5f, 0.5f, 1}, {0.f, 0.5f, 1}, {0.5f, 0.5f, 1},  // collinear
                                             {0, 1, 1},        {0, 1, 1},       {0, 1, 1},        // one point
                                             {-1, 0.2f, 1.5f}, {1, 0.2f, 1.5f}, {0, 0.2f + 1e-7f, 1.5f}};  // needle
                              m.indices = {0, 1, 2, 3, 4, 5, 6, 7, 8};
                              m.material = 0;
                              add_mesh(s, m);
                          }),
                          "zero-area and needle triangles");
    expect_finite_renders(damaged_scene([](Scene& s) {
                              for (Vec3f& n : s.meshes[0].normals) n = Vec3f(0.f);  // zero-length normals
                          }),
                          "zero normals");
    expect_finite_renders(damaged_scene([](Scene& s) {
                              // A tiny triangle with denormal coordinates, and denormal offsets elsewhere.
                              Mesh m;
                              m.positions = {{0, 0.5f, 0}, {kDenormal, 0.5f, 0}, {0, 0.5f + kDenormal, 0}};
                              m.indices = {0, 1, 2};
                              add_mesh(s, m);
                              s.meshes[0].positions[0].y = kDenormal;
                          }),
                          "denormals");
    expect_finite_renders(damaged_scene([](Scene& s) {
                              Sphere bad;
                              bad.center = {kNaN, 0, 0};
                              s.spheres.push_back(bad);
                              Sphere neg;
                              neg.radius = -1.0;
                              s.spheres.push_back(neg);
                              Plane zero;
                              zero.normal = {0, 0, 0};
                              s.planes.push_back(zero);
                          }),
                          "invalid spheres and planes");
}

TEST(StressBadInput, CameraAndLightPlacement) {
    expect_finite_renders(damaged_scene([](Scene& s) {
                              s.cameras[0] = make_camera(CameraType::Perspective, {-0.5, 0.5, -0.5}, {0, 0, -1}, {0, 1, 0}, 1.5);
                          }),
                          "camera inside the glass box");
    expect_finite_renders(damaged_scene([](Scene& s) { s.cameras[0].znear = 0.0; }), "znear 0");
    expect_finite_renders(damaged_scene([](Scene& s) {
                              s.cameras[0].type = CameraType::Orthographic;
                              s.cameras[0].xmag = s.cameras[0].ymag = 3.0;
                              s.cameras[0].znear = 0.0;
                          }),
                          "orthographic znear 0");
    expect_finite_renders(damaged_scene([](Scene& s) { s.lights[0].position = {0.25, 0.0, 2.0}; }), "light on the floor");
    expect_finite_renders(damaged_scene([](Scene& s) { s.lights[0].position = {1.0, 0.5, 1.0}; }),
                          "light on the sphere");
    expect_finite_renders(damaged_scene([](Scene& s) { s.materials[0].classic.emission = Color(3e38f); }),
                          "emission near FLT_MAX");
}

// The film's last line of defence: counts and zeroes what slipped through (release builds; a
// debug build treats it as a bug and throws).
TEST(StressBadInput, FilmSanitizesNonFiniteValues) {
    Film f(2, 2, PixelWindow{0, 0, 2, 2}, AovSet{});
    f.beauty[1] = Color(kNaN, 1.f, kInf);
    EXPECT_EQ(f.nonfinite_values(), 2u);
#ifdef NDEBUG
    EXPECT_EQ(f.sanitize_nonfinite(), 2u);
    EXPECT_EQ(f.beauty[1], Color(0.f, 1.f, 0.f));
#else
    EXPECT_THROW(f.sanitize_nonfinite(), Error);
#endif
    EXPECT_EQ(f.nonfinite_values(), 0u);
}

}  // namespace
}  // namespace whitted::stress
