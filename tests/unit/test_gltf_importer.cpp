// glTF importer: sample models checked against numbers read by hand from their JSON, and
// hand-made hostile files written to a scratch directory.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include <gtest/gtest.h>
#include <webp/encode.h>
#include <meshoptimizer.h>
#include <fmt/format.h>

#include "tests/support/test_importer_util.h"

namespace whitted::test {
namespace {

const Instance* instance_of_node(const Scene& s, const std::string& node_name) {
    for (const Instance& i : s.instances)
        if (i.node_name == node_name) return &i;
    return nullptr;
}

const Material* material_named(const Scene& s, const std::string& name) {
    for (const Material& m : s.materials)
        if (m.name == name) return &m;
    return nullptr;
}

bool has_warning(const Scene& s, const std::string& text) {
    return std::any_of(s.warnings.begin(), s.warnings.end(),
                       [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

size_t warnings_containing(const Scene& s, const std::string& text) {
    return size_t(std::count_if(s.warnings.begin(), s.warnings.end(),
                                [&](const std::string& w) { return w.find(text) != std::string::npos; }));
}

const ExtensionUse* extension(const Scene& s, const std::string& name) {
    for (const ExtensionUse& e : s.extensions)
        if (e.name == name) return &e;
    return nullptr;
}

Vec3f face_normal(const Mesh& m, size_t t) {
    const Vec3f a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
                c = m.positions[m.indices[3 * t + 2]];
    return cross(b - a, c - a);
}

// ---------------------------------------------------------------------------------------------
// Sample models

TEST(GltfImporter, BoxGeometryMaterialAndNodeMatrix) {
    const Scene s = load_scene(asset("Box/glTF/Box.gltf"));
    ASSERT_EQ(s.meshes.size(), 1u);
    ASSERT_EQ(s.instances.size(), 1u);
    const Mesh& m = s.meshes[0];
    EXPECT_EQ(m.positions.size(), 24u);
    EXPECT_EQ(m.triangle_count(), 12u);
    EXPECT_EQ(m.name, "Mesh/0");
    // accessor 2 element 0 = (-0.5, -0.5, 0.5), accessor 1 element 0 = (0, 0, 1); indices 0 1 2 3 2 1.
    EXPECT_VEC3_NEAR(m.positions[0], -0.5f, -0.5f, 0.5f, 0);
    EXPECT_VEC3_NEAR(m.normals[0], 0.f, 0.f, 1.f, 0);
    EXPECT_EQ((std::vector<uint32_t>(m.indices.begin(), m.indices.begin() + 6)),
              (std::vector<uint32_t>{0, 1, 2, 3, 2, 1}));
    // Material "Red": baseColorFactor (0.8, 0, 0, 1), metallic 0, roughness default 1.
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].name, "Red");
    EXPECT_FLOAT_EQ(s.materials[0].base_color.x, 0.8f);
    EXPECT_FLOAT_EQ(s.materials[0].metallic, 0.f);
    EXPECT_FLOAT_EQ(s.materials[0].roughness, 1.f);
    EXPECT_EQ(m.material, 0u);
    // Node 0 matrix (column-major) [1,0,0,0, 0,0,-1,0, 0,1,0,0, 0,0,0,1]: y' = z, z' = -y.
    const Mat4d& w = s.instances[0].world_from_object;
    EXPECT_EQ(w(1, 2), 1.0);
    EXPECT_EQ(w(2, 1), -1.0);
    EXPECT_EQ(w(1, 1), 0.0);
    EXPECT_EQ(s.instances[0].node, 1);
}

TEST(GltfImporter, ExternalEmbeddedAndBinaryVariantsAreIdentical) {
    const Scene a = load_scene(asset("Box/glTF/Box.gltf"));
    const Scene b = load_scene(asset("Box/glTF-Embedded/Box.gltf"));
    const Scene c = load_scene(asset("Box/glTF-Binary/Box.glb"));
    for (const Scene* s : {&b, &c}) {
        ASSERT_EQ(s->meshes.size(), a.meshes.size());
        EXPECT_EQ(s->meshes[0].positions, a.meshes[0].positions);
        EXPECT_EQ(s->meshes[0].normals, a.meshes[0].normals);
        EXPECT_EQ(s->meshes[0].indices, a.meshes[0].indices);
        EXPECT_EQ(s->instances[0].world_from_object, a.instances[0].world_from_object);
    }
    // BoxInterleaved holds the same box with POSITION and NORMAL interleaved (byteStride 24).
    const Scene d = load_scene(asset("BoxInterleaved/glTF-Binary/BoxInterleaved.glb"));
    EXPECT_EQ(d.meshes[0].positions, a.meshes[0].positions);
    EXPECT_EQ(d.meshes[0].normals, a.meshes[0].normals);
    EXPECT_EQ(d.meshes[0].indices, a.meshes[0].indices);
}

TEST(GltfImporter, TexturedBoxDecodesItsTexture) {
    const Scene s = load_scene(asset("BoxTextured/glTF/BoxTextured.gltf"));
    ASSERT_EQ(s.textures.size(), 1u);
    const Texture& t = s.textures[0];
    EXPECT_TRUE(t.srgb);
    ASSERT_FALSE(t.levels.empty());
    EXPECT_EQ(t.levels[0].width, 256);
    EXPECT_EQ(t.levels[0].height, 256);
    EXPECT_EQ(t.levels[0].texels.size(), 256u * 256u * 4u);
    EXPECT_EQ(t.levels.size(), 9u);  // 256 .. 1
    // Sampler: magFilter LINEAR, minFilter NEAREST_MIPMAP_LINEAR, REPEAT.
    EXPECT_EQ(t.mag_filter, FilterMode::Linear);
    EXPECT_EQ(t.min_filter, FilterMode::Nearest);
    EXPECT_TRUE(t.use_mips);
    EXPECT_EQ(t.wrap_s, WrapMode::Repeat);
    EXPECT_EQ(s.materials[0].base_color_texture.texture, 0);
    EXPECT_EQ(s.meshes[0].uv0.size(), s.meshes[0].positions.size());
    // load_textures = false: the same entry, without texels.
    const Scene n = load_scene(asset("BoxTextured/glTF/BoxTextured.gltf"), no_textures());
    ASSERT_EQ(n.textures.size(), 1u);
    EXPECT_TRUE(n.textures[0].levels.empty());
    EXPECT_EQ(n.textures[0].image, 0);
}

/// glTF URIs are percent-encoded (RFC 3986): "Cesium%20Logo.png" names the file "Cesium Logo.png".
TEST(GltfImporter, PercentEncodedUrisNameTheDecodedFile) {
    namespace fs = std::filesystem;
    const fs::path dir = scratch_dir() / "percent_uri";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path src = asset("BoxTextured/glTF");
    fs::copy_file(src / "BoxTextured0.bin", dir / "Box Textured 0.bin");
    fs::copy_file(src / "CesiumLogoFlat.png", dir / "Cesium Logo #1.png");
    const std::vector<uint8_t> bytes = read_bytes((src / "BoxTextured.gltf").string());
    std::string text(bytes.begin(), bytes.end());
    auto replace = [&](const std::string& from, const std::string& to) {
        const size_t at = text.find(from);
        ASSERT_NE(at, std::string::npos) << from;
        text.replace(at, from.size(), to);
    };
    replace("\"CesiumLogoFlat.png\"", "\"Cesium%20Logo%20%231.png\"");
    replace("\"BoxTextured0.bin\"", "\"Box%20Textured%200.bin\"");
    std::ofstream(dir / "box.gltf") << text;
    const Scene s = load_scene((dir / "box.gltf").string());
    ASSERT_EQ(s.textures.size(), 1u);
    ASSERT_FALSE(s.textures[0].levels.empty());
    EXPECT_EQ(s.textures[0].levels[0].width, 256);
    EXPECT_EQ(s.meshes[0].triangle_count(), 12u);
}

TEST(GltfImporter, VertexColorsVec3GetAlphaOne) {
    const Scene s = load_scene(asset("BoxVertexColors/glTF-Binary/BoxVertexColors.glb"));
    const Mesh& m = s.meshes[0];
    ASSERT_EQ(m.colors.size(), 24u);
    // COLOR_0 (accessor 3, VEC3 FLOAT) element 1 = (1, 0, 0).
    EXPECT_EQ(m.colors[1], Vec4f(1.f, 0.f, 0.f, 1.f));
    EXPECT_EQ(m.colors[2], Vec4f(1.f, 1.f, 0.f, 1.f));
}

TEST(GltfImporter, CamerasArePlacedByTheirNodes) {
    const Scene s = load_scene(asset("Cameras/glTF/Cameras.gltf"));
    ASSERT_EQ(s.cameras.size(), 2u);
    const Camera& p = s.cameras[0];
    EXPECT_EQ(p.type, CameraType::Perspective);
    EXPECT_DOUBLE_EQ(p.yfov, 0.7);
    EXPECT_DOUBLE_EQ(p.aspect, 1.0);
    EXPECT_DOUBLE_EQ(p.znear, 0.01);
    EXPECT_DOUBLE_EQ(p.zfar, 100.0);
    EXPECT_FALSE(p.is_default);
    const Vec3d pos = p.world_from_camera.apply_point(Vec3d(0.0));
    EXPECT_VEC3_NEAR(pos, 0.5, 0.5, 3.0, 0);
    const Camera& o = s.cameras[1];
    EXPECT_EQ(o.type, CameraType::Orthographic);
    EXPECT_DOUBLE_EQ(o.xmag, 1.0);
    EXPECT_DOUBLE_EQ(o.ymag, 1.0);
    EXPECT_DOUBLE_EQ(o.zfar, 100.0);
    // The mesh node's rotation (-0.383, 0, 0, 0.92375) is normalized before use (~ -45 deg about X).
    const Mat4d& w = s.instances[0].world_from_object;
    EXPECT_NEAR(w(1, 1), std::cos(std::numbers::pi / 4), 1e-3);
    EXPECT_NEAR(w(2, 1), -std::sin(std::numbers::pi / 4), 1e-3);
    EXPECT_NEAR(w.det3(), 1.0, 1e-12);
}

TEST(GltfImporter, DuckCameraUnderScaledParent) {
    const Scene s = load_scene(asset("Duck/glTF-Binary/Duck.glb"));
    ASSERT_EQ(s.cameras.size(), 1u);
    const Camera& c = s.cameras[0];
    EXPECT_DOUBLE_EQ(c.yfov, 0.6605925559997559);
    EXPECT_DOUBLE_EQ(c.aspect, 1.5);
    EXPECT_DOUBLE_EQ(c.znear, 1.0);
    EXPECT_DOUBLE_EQ(c.zfar, 10000.0);
    // Parent scale 0.009999999776482582 times the camera node's translation (400.113, 463.264, -431.078).
    const double k = 0.009999999776482582;
    const Vec3d pos = c.world_from_camera.apply_point(Vec3d(0.0));
    EXPECT_VEC3_NEAR(pos, k * 400.1130065917969, k * 463.2640075683594, k * -431.0780334472656, 1e-12);
    const Vec3d fwd = normalize(c.world_from_camera.apply_vector({0, 0, -1}));
    EXPECT_VEC3_NEAR(fwd, -0.5364750623703003, -0.6211478114128113, 0.571287989616394, 1e-6);
    EXPECT_EQ(s.instanced_triangle_count(), 4212u);
    ASSERT_EQ(s.textures.size(), 1u);
    EXPECT_FALSE(s.textures[0].levels.empty());
}

TEST(GltfImporter, SharedMeshBecomesOneMeshWithSeveralInstances) {
    const Scene s = load_scene(asset("SimpleMeshes/glTF/SimpleMeshes.gltf"));
    ASSERT_EQ(s.meshes.size(), 1u);
    ASSERT_EQ(s.instances.size(), 2u);
    EXPECT_EQ(s.instances[0].mesh, 0u);
    EXPECT_EQ(s.instances[1].mesh, 0u);
    EXPECT_EQ(s.instances[1].world_from_object(0, 3), 1.0);
    EXPECT_EQ(s.instanced_triangle_count(), 2u);
    EXPECT_EQ(s.mesh_triangle_count(), 1u);
}

TEST(GltfImporter, SparseAccessorValuesSubstituted) {
    const Scene s = load_scene(asset("SimpleSparseAccessor/glTF/SimpleSparseAccessor.gltf"));
    const Mesh& m = s.meshes[0];
    ASSERT_EQ(m.positions.size(), 14u);
    EXPECT_EQ(m.triangle_count(), 12u);
    // Sparse indices 8, 10, 12 replace y = 1 by 2, 3, 4; the others keep the bufferView values.
    EXPECT_EQ(m.positions[7], Vec3f(0.f, 1.f, 0.f));
    EXPECT_EQ(m.positions[8], Vec3f(1.f, 2.f, 0.f));
    EXPECT_EQ(m.positions[9], Vec3f(2.f, 1.f, 0.f));
    EXPECT_EQ(m.positions[10], Vec3f(3.f, 3.f, 0.f));
    EXPECT_EQ(m.positions[12], Vec3f(5.f, 4.f, 0.f));
    // No NORMAL in the file: smooth normals of a flat CCW grid in the XY plane point at +Z.
    for (const Vec3f& n : m.normals) EXPECT_NEAR(n.z, 1.f, 1e-6f);
}

TEST(GltfImporter, GpuInstancingMakesOneInstancePerEntry) {
    const Scene s = load_scene(asset("SimpleInstancing/glTF-Binary/SimpleInstancing.glb"));
    ASSERT_EQ(s.meshes.size(), 1u);
    ASSERT_EQ(s.instances.size(), 125u);
    EXPECT_EQ(s.instanced_triangle_count(), 1500u);
    for (const Instance& i : s.instances) EXPECT_EQ(i.mesh, 0u);
    // Instance 1: T (0, 0, 2.5), R quaternion (0, 0, 0.0496667, 0.9987658), S (1, 1, 1.25).
    const Mat4d& w = s.instances[1].world_from_object;
    EXPECT_NEAR(w(2, 3), 2.5, 1e-12);
    EXPECT_NEAR(w(2, 2), 1.25, 1e-9);
    const double qz = 0.04966672137379646, qw = 0.9987658262252808, n = std::hypot(qz, qw);
    EXPECT_NEAR(w(0, 0), 1 - 2 * (qz / n) * (qz / n), 1e-9);
    EXPECT_NEAR(w(1, 0), 2 * (qz / n) * (qw / n), 1e-9);
    // No material in the file: one default material (white, metallic 1, roughness 1).
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].name, "default");
    EXPECT_EQ(s.materials[0].base_color, Vec4f(1.f));
    EXPECT_EQ(s.materials[0].metallic, 1.f);
    EXPECT_EQ(s.materials[0].roughness, 1.f);
    ASSERT_NE(extension(s, "EXT_mesh_gpu_instancing"), nullptr);
    EXPECT_EQ(extension(s, "EXT_mesh_gpu_instancing")->support, ExtensionSupport::Supported);
}

TEST(GltfImporter, PrimitiveModesStripAndFan) {
    const Scene s = load_scene(asset("MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf"));
    // POINTS, LINES, LINE_LOOP, LINE_STRIP skipped with one warning; TRIANGLES 18/3, STRIP 6-2, FAN 8-2.
    ASSERT_EQ(s.meshes.size(), 3u);
    EXPECT_EQ(s.meshes[0].triangle_count(), 6u);
    EXPECT_EQ(s.meshes[1].triangle_count(), 4u);
    EXPECT_EQ(s.meshes[2].triangle_count(), 6u);
    EXPECT_EQ(s.instanced_triangle_count(), 16u);
    EXPECT_EQ(warnings_containing(s, "POINTS, LINES, LINE_LOOP or LINE_STRIP"), 1u);
    EXPECT_TRUE(has_warning(s, "4 primitive(s)"));
    // Strip indices 2 3 1 4 6 5: triangle 1 is {v1, v3, v2} = (3, 4, 1). Fan 0 1 2 ..: (1, 2, 0).
    const Mesh& strip = s.meshes[1];
    EXPECT_EQ((std::vector<uint32_t>(strip.indices.begin(), strip.indices.begin() + 6)),
              (std::vector<uint32_t>{2, 3, 1, 3, 4, 1}));
    const Mesh& fan = s.meshes[2];
    EXPECT_EQ((std::vector<uint32_t>(fan.indices.begin(), fan.indices.begin() + 3)), (std::vector<uint32_t>{1, 2, 0}));
    EXPECT_EQ((std::vector<uint32_t>(fan.indices.end() - 3, fan.indices.end())), (std::vector<uint32_t>{6, 1, 0}));
    // Every triangle of all three comes out counter-clockwise seen from +Z.
    for (const Mesh& m : s.meshes)
        for (size_t t = 0; t < m.triangle_count(); ++t) EXPECT_GT(face_normal(m, t).z, 0.f) << m.name << " " << t;
}

TEST(GltfImporter, MultipleScenesUsesDefaultOrRequestedScene) {
    const std::string path = asset("MultipleScenes/glTF/MultipleScenes.gltf");
    const Scene def = load_scene(path);  // "scene": 1 -> mesh 1, a 2-triangle quad
    EXPECT_EQ(def.instanced_triangle_count(), 2u);
    ImportOptions o;
    o.scene_index = 0;
    EXPECT_EQ(load_scene(path, o).instanced_triangle_count(), 1u);
    o.scene_index = 2;
    const std::string err = error_text([&] { load_scene(path, o); });
    EXPECT_NE(err.find("/scenes"), std::string::npos) << err;
    EXPECT_NE(err.find("scene 2 requested but the file has 2"), std::string::npos) << err;
}

TEST(GltfImporter, NegativeScaleFlipsWindingWithOneMeshPerSign) {
    const Scene s = load_scene(asset("NegativeScaleTest/glTF-Binary/NegativeScaleTest.glb"), no_textures());
    // Meshes 5, 6, 7 are each used with both signs, mesh 4 only mirrored, meshes 0-3 only direct.
    EXPECT_EQ(s.instances.size(), 11u);
    EXPECT_EQ(s.meshes.size(), 11u);
    size_t mirrored = 0;
    for (const Mesh& m : s.meshes) mirrored += m.name.find("(mirrored)") != std::string::npos;
    EXPECT_EQ(mirrored, 4u);
    EXPECT_EQ(s.instanced_triangle_count(), 7724u);
    for (const Instance& inst : s.instances) {
        const Mesh& m = s.meshes[inst.mesh];
        const bool neg = inst.world_from_object.det3() < 0;
        EXPECT_EQ(neg, m.name.find("(mirrored)") != std::string::npos) << inst.node_name;
        // Fronts agree with the shading normals in world space (normals transform by M^-T).
        const Mat4d nm = inst.world_from_object.inverse_affine().transposed();
        for (size_t t = 0; t < std::min<size_t>(m.triangle_count(), 64); ++t) {
            const Vec3d p0 = inst.world_from_object.apply_point(Vec3d(m.positions[m.indices[3 * t]]));
            const Vec3d p1 = inst.world_from_object.apply_point(Vec3d(m.positions[m.indices[3 * t + 1]]));
            const Vec3d p2 = inst.world_from_object.apply_point(Vec3d(m.positions[m.indices[3 * t + 2]]));
            const Vec3d ng = cross(p1 - p0, p2 - p0);
            Vec3d ns(0.0);
            for (int k = 0; k < 3; ++k) ns += nm.apply_vector(Vec3d(m.normals[m.indices[3 * t + size_t(k)]]));
            if (length(ng) < 1e-12) continue;
            EXPECT_GT(dot(ng, ns), 0.0) << inst.node_name << " triangle " << t;
        }
    }
    // NotShiny1 (+) and NotShinyMinus1 (-) share glTF mesh 5: the mirrored copy swaps two indices.
    const Instance* pos = instance_of_node(s, "NotShiny1");
    const Instance* neg = instance_of_node(s, "NotShinyMinus1");
    ASSERT_TRUE(pos && neg);
    const Mesh& a = s.meshes[pos->mesh];
    const Mesh& b = s.meshes[neg->mesh];
    ASSERT_NE(pos->mesh, neg->mesh);
    ASSERT_EQ(a.indices.size(), b.indices.size());
    EXPECT_EQ(a.positions, b.positions);
    for (size_t t = 0; t < a.triangle_count(); ++t) {
        EXPECT_EQ(a.indices[3 * t], b.indices[3 * t]);
        EXPECT_EQ(a.indices[3 * t + 1], b.indices[3 * t + 2]);
        EXPECT_EQ(a.indices[3 * t + 2], b.indices[3 * t + 1]);
    }
}

TEST(GltfImporter, OrientationTestTransforms) {
    const Scene s = load_scene(asset("OrientationTest/glTF-Binary/OrientationTest.glb"));
    EXPECT_EQ(s.instances.size(), 13u);
    EXPECT_EQ(s.instanced_triangle_count(), 524u);
    // ArrowY1: rotation (0, -0.5735765, 0, 0.8191521) (-70 deg about Y), translation (0, 5, 0).
    const Instance* y1 = instance_of_node(s, "ArrowY1");
    ASSERT_NE(y1, nullptr);
    EXPECT_NEAR(y1->world_from_object(1, 3), 5.0, 0);
    EXPECT_NEAR(y1->world_from_object(0, 0), std::cos(70.0 * std::numbers::pi / 180), 1e-6);
    EXPECT_NEAR(y1->world_from_object(0, 2), -std::sin(70.0 * std::numbers::pi / 180), 1e-6);
    // ArrowX2: column-major matrix, column 1 = (0, 0.9961947, 0.0871557), translation (-5, 0, 0).
    const Instance* x2 = instance_of_node(s, "ArrowX2");
    ASSERT_NE(x2, nullptr);
    EXPECT_DOUBLE_EQ(x2->world_from_object(2, 1), 0.08715572783347625);
    EXPECT_DOUBLE_EQ(x2->world_from_object(1, 2), -0.08715572783347625);
    EXPECT_DOUBLE_EQ(x2->world_from_object(0, 3), -5.0);
}

TEST(GltfImporter, TriangleWithAndWithoutIndicesAgree) {
    const Scene a = load_scene(asset("Triangle/glTF/Triangle.gltf"));
    const Scene b = load_scene(asset("TriangleWithoutIndices/glTF/TriangleWithoutIndices.gltf"));
    ASSERT_EQ(a.meshes.size(), 1u);
    ASSERT_EQ(b.meshes.size(), 1u);
    EXPECT_EQ(a.meshes[0].positions, b.meshes[0].positions);
    EXPECT_EQ(a.meshes[0].indices, b.meshes[0].indices);
    EXPECT_EQ(b.meshes[0].indices, (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_EQ(b.meshes[0].positions[1], Vec3f(1.f, 0.f, 0.f));
    for (const Vec3f& n : b.meshes[0].normals) EXPECT_EQ(n, Vec3f(0.f, 0.f, 1.f));
}

TEST(GltfImporter, TextureTransformAndSamplers) {
    const Scene s = load_scene(asset("TextureTransformTest/glTF/TextureTransformTest.gltf"), no_textures());
    const Material* offset_u = material_named(s, "Offset U");
    const Material* rotation = material_named(s, "Rotation");
    const Material* all = material_named(s, "All");
    ASSERT_TRUE(offset_u && rotation && all);
    EXPECT_EQ(offset_u->base_color_texture.transform.offset, Vec2f(0.5f, 0.f));
    EXPECT_TRUE(offset_u->base_color_texture.transform.scale == Vec2f(1.f, 1.f));
    EXPECT_FLOAT_EQ(rotation->base_color_texture.transform.rotation, 0.39269908169872414f);
    EXPECT_EQ(all->base_color_texture.transform.offset, Vec2f(-0.2f, -0.1f));
    EXPECT_FLOAT_EQ(all->base_color_texture.transform.rotation, 0.3f);
    EXPECT_EQ(all->base_color_texture.transform.scale, Vec2f(1.5f, 1.5f));
    EXPECT_EQ(all->base_color_texture.uv_set, 0u);
    // Five glTF textures, all used as base color (sRGB) -> five Scene textures.
    ASSERT_EQ(s.textures.size(), 5u);
    const Texture& uv = s.textures[size_t(offset_u->base_color_texture.texture)];
    EXPECT_EQ(uv.wrap_s, WrapMode::ClampToEdge);
    EXPECT_EQ(uv.wrap_t, WrapMode::ClampToEdge);
    EXPECT_FALSE(uv.use_mips);  // minFilter LINEAR
    const Material* correct = material_named(s, "Correct");
    ASSERT_NE(correct, nullptr);
    const Texture& no_sampler = s.textures[size_t(correct->base_color_texture.texture)];
    EXPECT_EQ(no_sampler.wrap_s, WrapMode::Repeat);
    EXPECT_EQ(no_sampler.mag_filter, FilterMode::Linear);
    EXPECT_TRUE(no_sampler.use_mips);
    EXPECT_EQ(s.instances.size(), 12u);
}

TEST(GltfImporter, TextureSettingsWrapModesAndDecoding) {
    const Scene s = load_scene(asset("TextureSettingsTest/glTF-Binary/TextureSettingsTest.glb"));
    auto texture = [&](const std::string& name) -> const Texture& {
        for (const Texture& t : s.textures)
            if (t.name == name) return t;
        ADD_FAILURE() << name;
        return s.textures[0];
    };
    EXPECT_EQ(texture("TextureMirrorTextureT").wrap_t, WrapMode::MirroredRepeat);
    EXPECT_EQ(texture("TextureMirrorTextureS").wrap_s, WrapMode::MirroredRepeat);
    EXPECT_EQ(texture("TextureClampTextureT").wrap_t, WrapMode::ClampToEdge);
    EXPECT_EQ(texture("TextureClampTextureT").wrap_s, WrapMode::Repeat);
    EXPECT_EQ(texture("TextureRepeatTextureT").wrap_s, WrapMode::ClampToEdge);
    // Images come from bufferViews of the GLB, decoded after validation.
    EXPECT_EQ(texture("LabelTexture").levels.at(0).width, 256);
    EXPECT_EQ(texture("DoubleSidedTexture").levels.at(0).width, 512);
    EXPECT_EQ(s.instanced_triangle_count(), 72u);
}

TEST(GltfImporter, UnlitMaterials) {
    const Scene s = load_scene(asset("UnlitTest/glTF-Binary/UnlitTest.glb"));
    ASSERT_EQ(s.materials.size(), 2u);
    for (const Material& m : s.materials) EXPECT_TRUE(m.unlit);
    EXPECT_EQ(s.materials[0].base_color, Vec4f(1.f, 0.217637640824031f, 0.f, 1.f));
    const ExtensionUse* e = extension(s, "KHR_materials_unlit");
    ASSERT_NE(e, nullptr);
    EXPECT_EQ(e->support, ExtensionSupport::Supported);
    EXPECT_TRUE(e->required);
    // Both meshes share geometry accessors but not materials: two meshes, one decode.
    ASSERT_EQ(s.meshes.size(), 2u);
    EXPECT_EQ(s.meshes[0].positions, s.meshes[1].positions);
    EXPECT_NE(s.meshes[0].material, s.meshes[1].material);
}

TEST(GltfImporter, EmissiveStrength) {
    const Scene s = load_scene(asset("EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb"), no_textures());
    const Material* e4 = material_named(s, "Emit4");
    const Material* e1 = material_named(s, "Emit1");
    const Material* e16 = material_named(s, "Emit16");
    ASSERT_TRUE(e4 && e1 && e16);
    EXPECT_EQ(e4->emissive, Color(0.1f, 0.5f, 0.9f));
    EXPECT_FLOAT_EQ(e4->emissive_strength, 4.f);
    EXPECT_FLOAT_EQ(e1->emissive_strength, 1.f);
    EXPECT_FLOAT_EQ(e16->emissive_strength, 16.f);
    EXPECT_EQ(s.instances.size(), 6u);
}

TEST(GltfImporter, SpecularExtension) {
    const Scene s = load_scene(asset("SpecularTest/glTF-Binary/SpecularTest.glb"), no_textures());
    ASSERT_EQ(s.materials.size(), 24u);
    EXPECT_FLOAT_EQ(s.materials[1].specular, 0.f);
    EXPECT_FLOAT_EQ(s.materials[2].specular, 0.051269f);
    EXPECT_EQ(s.materials[10].specular_color, Color(0.520996f));
    EXPECT_EQ(s.materials[17].specular_color, Color(1.f, 1.f, 0.f));
    EXPECT_EQ(s.materials[21].specular_color, Color(5.441f));
    // M2_SpecTex: specularTexture (linear, A); M4_whiteTex: specularColorTexture (sRGB).
    const TextureRef& spec = s.materials[6].specular_texture;
    const TextureRef& color = s.materials[12].specular_color_texture;
    ASSERT_TRUE(spec.valid());
    ASSERT_TRUE(color.valid());
    EXPECT_FALSE(s.textures[size_t(spec.texture)].srgb);
    EXPECT_TRUE(s.textures[size_t(color.texture)].srgb);
    EXPECT_EQ(s.instanced_triangle_count(), 44828u);
}

TEST(GltfImporter, TransmissionAndVolume) {
    const Scene s = load_scene(asset("AttenuationTest/glTF-Binary/AttenuationTest.glb"), no_textures());
    const Material& m = s.materials[0];  // "R2_and_R4_ThicknessFac_1.0"
    EXPECT_FLOAT_EQ(m.transmission, 1.f);
    EXPECT_TRUE(m.has_volume);
    EXPECT_FLOAT_EQ(m.thickness, 1.f);
    EXPECT_EQ(m.attenuation_color, Color(0.1f, 0.5f, 0.9f));
    EXPECT_FLOAT_EQ(m.attenuation_distance, 1.f);
    EXPECT_FLOAT_EQ(s.materials[8].attenuation_distance, 0.6666666667f);
    EXPECT_FLOAT_EQ(m.roughness, 0.f);
    // R3 uses a thicknessTexture: not read, one warning.
    EXPECT_TRUE(has_warning(s, "thicknessTexture not used"));
    EXPECT_EQ(s.instanced_triangle_count(), 292u);
}

TEST(GltfImporter, GlassHurricaneCandleHolder) {
    const Scene s =
        load_scene(asset("GlassHurricaneCandleHolder/glTF-Binary/GlassHurricaneCandleHolder.glb"), no_textures());
    ASSERT_EQ(s.materials.size(), 2u);
    const Material& glass = s.materials[1];
    EXPECT_EQ(glass.name, "GlassHurricaneCandleHolder-glass");
    EXPECT_FLOAT_EQ(glass.transmission, 1.f);
    EXPECT_TRUE(glass.has_volume);
    EXPECT_FLOAT_EQ(glass.thickness, 0.1f);
    EXPECT_FLOAT_EQ(glass.attenuation_distance, 0.001f);
    EXPECT_EQ(glass.attenuation_color, Color(0.8f, 0.95f, 1.f));
    // Texture 0 is both metallicRoughness and occlusion (linear): one Scene texture; texture 1
    // is base color (sRGB); texture 2 (thickness) is not used.
    EXPECT_EQ(glass.occlusion_texture.texture, glass.metallic_roughness_texture.texture);
    ASSERT_EQ(s.textures.size(), 2u);
    EXPECT_TRUE(s.textures[size_t(glass.base_color_texture.texture)].srgb);
    EXPECT_FALSE(s.textures[size_t(glass.occlusion_texture.texture)].srgb);
    EXPECT_TRUE(s.textures[0].use_mips);  // LINEAR_MIPMAP_LINEAR
    EXPECT_EQ(s.instanced_triangle_count(), 4126u);
    // Node 1: rotation (0.7071068, 0, 0, 0.7071067), +90 degrees about X: y' = -z, z' = y.
    const Instance* g = instance_of_node(s, "GlassHurricaneCandleHolder-glass");
    ASSERT_NE(g, nullptr);
    EXPECT_NEAR(g->world_from_object(1, 2), -1.0, 1e-6);
    EXPECT_NEAR(g->world_from_object(2, 1), 1.0, 1e-6);
}

TEST(GltfImporter, PunctualLightsFromNodes) {
    const Scene s = load_scene(asset("LightsPunctualLamp/glTF/LightsPunctualLamp.gltf"), no_textures());
    ASSERT_EQ(s.lights.size(), 5u);
    const Light& l0 = s.lights[0];
    EXPECT_EQ(l0.name, "Point");
    EXPECT_EQ(l0.type, LightType::Point);
    EXPECT_FLOAT_EQ(l0.intensity, 15.f);  // candela, used as is (docs/lights.md)
    EXPECT_EQ(l0.color, Color(1.f, 0.6318749785423279f, 0.23909975588321689f));
    EXPECT_EQ(l0.attenuation, Attenuation::InverseSquare);
    EXPECT_EQ(l0.range, 0.f);
    EXPECT_VEC3_NEAR(l0.position, 0.04622355476021767, 0.9077973365783693, 0.006696629337966442, 1e-12);
    // Node matrix maps -Z to (0, -1, ~0): the light node points down.
    EXPECT_VEC3_NEAR(l0.direction, 0.0, -1.0, 0.0, 1e-6);
    EXPECT_FALSE(l0.is_default);
    EXPECT_EQ(s.lights[1].color, Color(1.f));  // no color given
    EXPECT_FLOAT_EQ(s.lights[4].intensity, 180.f);
    EXPECT_EQ(s.lights[4].name, "Point.004");
    EXPECT_FALSE(has_warning(s, "default light"));
    // No camera in the file: the default one.
    ASSERT_EQ(s.cameras.size(), 1u);
    EXPECT_TRUE(s.cameras[0].is_default);
}

TEST(GltfImporter, MetalRoughSpheresLoadsQuickly) {
    const auto t0 = std::chrono::steady_clock::now();
    const Scene s = load_scene(asset("MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb"));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(s.instanced_triangle_count(), 1040409u);
    EXPECT_LT(seconds, 3.0);  // generous for a linear import; a quadratic step would show
    // The 98 spheres share one geometry (accessors 0, 26, 52) with 98 materials.
    size_t spheres = 0;
    for (const Mesh& m : s.meshes) spheres += m.positions.size() == 5374;
    EXPECT_EQ(spheres, 98u);
}

/// The default light, not the default studio environment (ImportOptions::default_environment).
ImportOptions default_light_options() {
    ImportOptions o;
    o.default_environment = false;
    return o;
}

// A glTF file with no lights and no environment is lit by the bundled studio map: its extracted
// lights replace the default light, and --no-environment (or default_environment = false) and a
// file with lights keep the old behaviour.
TEST(GltfImporter, DefaultStudioEnvironment) {
    const Scene s = load_scene(asset("Box/glTF/Box.gltf"));
    ASSERT_TRUE(s.environment);
    EXPECT_EQ(s.environment->image->name, "studio");
    ASSERT_FALSE(s.lights.empty());
    for (const Light& l : s.lights) {
        EXPECT_TRUE(l.from_environment);
        EXPECT_FALSE(l.is_default);
    }
    // The default light is gone, and so is the warning that announced it.
    for (const std::string& w : s.warnings) EXPECT_EQ(w.find("added the default light"), std::string::npos) << w;
    EXPECT_TRUE(s.environment->ambient_sh);
    ImportOptions none;
    none.no_environment = true;
    const Scene plain = load_scene(asset("Box/glTF/Box.gltf"), none);
    EXPECT_FALSE(plain.environment);
    ASSERT_EQ(plain.lights.size(), 1u);
    EXPECT_TRUE(plain.lights[0].is_default);
    const Scene lit = load_scene(asset("LightsPunctualLamp/glTF/LightsPunctualLamp.gltf"));
    EXPECT_FALSE(lit.environment);
}

TEST(GltfImporter, DefaultCameraAndLight) {
    const Scene s = load_scene(asset("Box/glTF/Box.gltf"), default_light_options());
    ASSERT_EQ(s.cameras.size(), 1u);
    const Camera& c = s.cameras[0];
    EXPECT_TRUE(c.is_default);
    EXPECT_EQ(c.type, CameraType::Perspective);
    EXPECT_DOUBLE_EQ(c.yfov, 0.8);
    // Looks at the bounds centre (the origin) from distance radius / sin(yfov / 2) * 1.1.
    const double radius = std::sqrt(3.0) / 2;
    const Vec3d eye = c.world_from_camera.apply_point(Vec3d(0.0));
    const Vec3d fwd = normalize(c.world_from_camera.apply_vector({0, 0, -1}));
    EXPECT_NEAR(length(eye), radius / std::sin(0.4) * 1.1, 1e-9);
    EXPECT_VEC3_NEAR(fwd, -eye.x / length(eye), -eye.y / length(eye), -eye.z / length(eye), 1e-12);
    EXPECT_GT(eye.z, 0.0);
    EXPECT_GT(eye.y, 0.0);
    const Vec3d up = c.world_from_camera.apply_vector({0, 1, 0});
    EXPECT_GT(up.y, 0.9);
    ASSERT_EQ(s.lights.size(), 1u);
    const Light& l = s.lights[0];
    EXPECT_TRUE(l.is_default);
    EXPECT_EQ(l.type, LightType::Directional);
    EXPECT_FLOAT_EQ(l.intensity, 1.f);
    EXPECT_EQ(l.attenuation, Attenuation::None);
    EXPECT_VEC3_NEAR(l.direction, 0.4 / std::sqrt(1.52), -1 / std::sqrt(1.52), -0.6 / std::sqrt(1.52), 1e-12);
    EXPECT_TRUE(has_warning(s, "no lights in the file: added the default light (see docs/lights.md)"));
    ImportOptions o = default_light_options();
    o.add_default_camera = false;
    o.add_default_light = false;
    const Scene bare = load_scene(asset("Box/glTF/Box.gltf"), o);
    EXPECT_TRUE(bare.cameras.empty());
    EXPECT_TRUE(bare.lights.empty());
}

TEST(GltfImporter, EveryCopiedModelLoads) {
    size_t files = 0;
    for (const auto& e : std::filesystem::recursive_directory_iterator(asset(""))) {
        const std::string ext = e.path().extension().string();
        if (ext != ".gltf" && ext != ".glb") continue;
        ++files;
        SCOPED_TRACE(e.path().string());
        Scene s;
        ASSERT_NO_THROW(s = load_scene(e.path().string(), no_textures()))
            << error_text([&] { load_scene(e.path().string(), no_textures()); });
        EXPECT_GT(s.instanced_triangle_count(), 0u);
        EXPECT_FALSE(s.materials.empty());
        EXPECT_FALSE(s.cameras.empty());
        EXPECT_FALSE(s.lights.empty());
        for (const Instance& i : s.instances) {
            EXPECT_LT(i.mesh, s.meshes.size());
            EXPECT_TRUE(i.world_from_object.is_finite());
        }
        for (const Mesh& m : s.meshes) {
            EXPECT_LT(m.material, s.materials.size());
            EXPECT_EQ(m.normals.size(), m.positions.size());
            for (uint32_t idx : m.indices) ASSERT_LT(idx, m.positions.size());
            for (const Vec3f& n : m.normals) ASSERT_NEAR(length(n), 1.f, 1e-4f);
        }
    }
    EXPECT_GE(files, 26u);
}

// ---------------------------------------------------------------------------------------------
// Dispatch and file-level errors

TEST(GltfImporter, DispatchIsCaseInsensitiveAndUnknownExtensionsAreNamed) {
    const std::string upper = write_file("BOX.GLB", read_bytes(asset("Box/glTF-Binary/Box.glb")));
    EXPECT_EQ(load_scene(upper).instanced_triangle_count(), 12u);
    const std::string obj = write_file("model.obj", std::string("v 0 0 0\n"));
    const std::string err = error_text([&] { load_scene(obj); });
    EXPECT_NE(err.find(obj), std::string::npos) << err;
    EXPECT_NE(err.find("'.obj'"), std::string::npos) << err;
    const std::string none = error_text([&] { load_scene(write_file("noext", std::string("{}"))); });
    EXPECT_NE(none.find("no extension"), std::string::npos) << none;
}

TEST(GltfImporter, MissingFileAndDirectoryAreErrors) {
    const std::string missing = (scratch_dir() / "does_not_exist.gltf").string();
    const std::string err = error_text([&] { load_scene(missing); });
    EXPECT_NE(err.find(missing), std::string::npos) << err;
    EXPECT_NE(err.find("cannot open"), std::string::npos) << err;
    const std::filesystem::path dir = scratch_dir() / "folder.gltf";
    std::filesystem::create_directories(dir);
    EXPECT_NE(error_text([&] { load_scene(dir.string()); }).find("directory"), std::string::npos);
}

TEST(GltfImporter, TruncatedGlbIsAnError) {
    std::vector<uint8_t> glb = read_bytes(asset("Box/glTF-Binary/Box.glb"));
    glb.resize(glb.size() - 100);
    const std::string err = error_text([&] { load_scene(write_file("truncated.glb", glb)); });
    EXPECT_NE(err.find("truncated GLB"), std::string::npos) << err;
}

TEST(GltfImporter, MemoryLimitIsChecked) {
    ImportOptions o = no_textures();
    o.max_memory = 60000;  // Duck.glb alone is ~120 kB
    const std::string err = error_text([&] { load_scene(asset("Duck/glTF-Binary/Duck.glb"), o); });
    EXPECT_NE(err.find("memory limit"), std::string::npos) << err;
    o.max_memory = 130000;  // the file fits, its vertex and index data do not
    const std::string err2 = error_text([&] { load_scene(asset("Duck/glTF-Binary/Duck.glb"), o); });
    EXPECT_NE(err2.find("ImportOptions::max_memory"), std::string::npos) << err2;
}

// ---------------------------------------------------------------------------------------------
// Hand-made files

/// A unit quad in the XY plane, CCW seen from +Z: 4 float positions (48 bytes) then 6 ushort
/// indices (12 bytes).
Bytes quad_bin() {
    Bytes b;
    b.put<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
    b.put<uint16_t>({0, 1, 2, 0, 2, 3});
    return b;
}

const char* kQuadJson = R"({
  "asset": {"version": "2.0"},
  "buffers": [{"uri": "$BUFFER", "byteLength": $LENGTH}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                  {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "nodes": [{"mesh": 0}],
  "scenes": [{"nodes": [0]}],
  "scene": 0
})";

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
    for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
        s.replace(at, from.size(), to);
    return s;
}

/// Replaces `from` (which must occur) by `to`.
std::string edit(const std::string& json, const std::string& from, const std::string& to) {
    EXPECT_NE(json.find(from), std::string::npos) << "test bug: '" << from << "' not in the JSON";
    return replace_all(json, from, to);
}

/// Writes the JSON with $BUFFER / $LENGTH filled from `bin`; returns the path.
std::string write_gltf(const std::string& name, const std::string& json, const Bytes& bin) {
    return write_file(
        name, replace_all(replace_all(json, "$BUFFER", data_uri(bin.data)), "$LENGTH", std::to_string(bin.size())));
}

TEST(GltfHandMade, QuadLoads) {
    const Scene s = load_scene(write_gltf("quad.gltf", kQuadJson, quad_bin()));
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(s.meshes[0].triangle_count(), 2u);
    for (const Vec3f& n : s.meshes[0].normals) EXPECT_EQ(n, Vec3f(0.f, 0.f, 1.f));  // generated
}

TEST(GltfHandMade, NodeWithTwoParents) {
    const std::string json =
        edit(kQuadJson, R"("nodes": [{"mesh": 0}])", R"("nodes": [{"children": [2]}, {"children": [2]}, {"mesh": 0}])");
    const std::string path =
        write_gltf("two_parents.gltf", edit(json, R"("nodes": [0])", R"("nodes": [0, 1])"), quad_bin());
    const std::string err = error_text([&] { load_scene(path); });
    EXPECT_NE(err.find(path + ": /nodes/2: node 2 has two parents (nodes 0 and 1)"), std::string::npos) << err;
}

TEST(GltfHandMade, NodeThatIsItsOwnChildAndNonRootSceneNode) {
    const std::string self =
        write_gltf("self_child.gltf", edit(kQuadJson, R"({"mesh": 0})", R"({"mesh": 0, "children": [0]})"), quad_bin());
    EXPECT_NE(error_text([&] { load_scene(self); }).find("/nodes/0/children/0: node 0 is its own child"),
              std::string::npos);
    const std::string json =
        edit(kQuadJson, R"("nodes": [{"mesh": 0}])", R"("nodes": [{"children": [1]}, {"mesh": 0}])");
    const std::string path =
        write_gltf("non_root.gltf", edit(json, R"("nodes": [0])", R"("nodes": [0, 1])"), quad_bin());
    EXPECT_NE(error_text([&] { load_scene(path); }).find("/scenes/0/nodes/1"), std::string::npos);
}

TEST(GltfHandMade, ErrorPointersJoinEveryIndex) {
    // Twelve nodes, the last faulty: its pointer has a two-digit index (joined from pieces).
    std::string nodes = R"("nodes": [{"mesh": 0})";
    for (int i = 1; i < 12; ++i) nodes += i == 11 ? R"(, {"children": [1, 13]})" : R"(, {})";
    const std::string path = write_gltf("pointer_indices.gltf", edit(kQuadJson, R"("nodes": [{"mesh": 0}])", nodes + "]"),
                                        quad_bin());
    const std::string err = error_text([&] { load_scene(path); });
    EXPECT_NE(err.find(path + ": /nodes/11/children/1: unresolved reference: node 13 does not exist (the file has 12)"),
              std::string::npos)
        << err;
}

TEST(GltfHandMade, HugeAccessorCountOverTinyBuffer) {
    const std::string path = write_gltf(
        "huge_count.gltf",
        edit(kQuadJson, R"("componentType": 5126, "count": 4)", R"("componentType": 5126, "count": 100000000)"),
        quad_bin());
    const std::string err = error_text([&] { load_scene(path); });
    EXPECT_NE(err.find("/accessors/0/count: 100000000 elements of 12 bytes"), std::string::npos) << err;
    EXPECT_NE(err.find("do not fit bufferView 0 (48 bytes)"), std::string::npos) << err;
}

TEST(GltfHandMade, ImplicitZeroAccessorBeyondMemoryLimit) {
    // No bufferView: count zeros. Nothing bounds them but ImportOptions::max_memory.
    const std::string json = edit(kQuadJson, R"({"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"})",
                                  R"({"componentType": 5126, "count": 1000000000000, "type": "VEC3"})");
    const std::string err = error_text([&] { load_scene(write_gltf("zeros.gltf", json, quad_bin())); });
    EXPECT_NE(err.find("/accessors/0/count"), std::string::npos) << err;
    EXPECT_NE(err.find("memory limit"), std::string::npos) << err;
}

TEST(GltfHandMade, NanPositionIsAnError) {
    Bytes b;
    b.put<float>({0, 0, 0, 1, 0, 0, 1, std::nanf(""), 0, 0, 1, 0});
    b.put<uint16_t>({0, 1, 2, 0, 2, 3});
    const std::string path = write_gltf("nan.gltf", kQuadJson, b);
    const std::string err = error_text([&] { load_scene(path); });
    EXPECT_NE(err.find("/meshes/0/primitives/0/attributes/POSITION"), std::string::npos) << err;
    EXPECT_NE(err.find("element 2 holds a NaN"), std::string::npos) << err;
}

TEST(GltfHandMade, RequiredExtensions) {
    const std::string unknown = write_gltf(
        "unknown_ext.gltf",
        edit(
            kQuadJson, R"("asset": {"version": "2.0"},)",
            R"("asset": {"version": "2.0"}, "extensionsUsed": ["EXT_unknown_thing"], "extensionsRequired": ["EXT_unknown_thing"],)"),
        quad_bin());
    const std::string err = error_text([&] { load_scene(unknown); });
    EXPECT_NE(err.find("/extensionsRequired/0: required extension EXT_unknown_thing is not supported"),
              std::string::npos)
        << err;
    // An extension refused when required (KTX2 textures) is named as that.
    const std::string basisu = write_gltf(
        "basisu.gltf",
        edit(
            kQuadJson, R"("asset": {"version": "2.0"},)",
            R"("asset": {"version": "2.0"}, "extensionsUsed": ["KHR_texture_basisu"], "extensionsRequired": ["KHR_texture_basisu"],)"),
        quad_bin());
    EXPECT_NE(error_text([&] { load_scene(basisu); }).find("required extension KHR_texture_basisu is not supported"),
              std::string::npos);
    // Used but not required: ignored with one warning each; an ignorable one may even be required.
    const std::string soft = write_gltf(
        "soft_ext.gltf",
        edit(
            kQuadJson, R"("asset": {"version": "2.0"},)",
            R"("asset": {"version": "2.0"}, "extensionsUsed": ["KHR_materials_volume_scatter", "EXT_foo", "KHR_xmp_json_ld"], "extensionsRequired": ["KHR_xmp_json_ld"],)"),
        quad_bin());
    const Scene s = load_scene(soft);
    ASSERT_EQ(s.extensions.size(), 3u);
    EXPECT_EQ(s.extensions[0].support, ExtensionSupport::Ignored);
    EXPECT_EQ(s.extensions[1].note, "unknown extension");
    EXPECT_TRUE(s.extensions[2].required);
    EXPECT_EQ(warnings_containing(s, "extension KHR_materials_volume_scatter ignored"), 1u);
    EXPECT_EQ(warnings_containing(s, "extension EXT_foo ignored"), 1u);
}

// Files name the extension they need, not its consequences: a primitive compressed by an unknown
// codec has accessors without bufferView (tinygltf would say "accessor[1] invalid bufferView"); in
// a .gltf and in a GLB's JSON chunk.
TEST(GltfHandMade, RequiredCompressionIsNamedBeforeItsConsequences) {
    const std::string other_json = R"({"asset": {"version": "2.0"},
      "extensionsUsed": ["EXT_other_mesh_compression"], "extensionsRequired": ["EXT_other_mesh_compression"],
      "buffers": [{"byteLength": 4, "uri": "data:application/octet-stream;base64,AAAAAA=="}],
      "bufferViews": [{"buffer": 0, "byteLength": 4}],
      "accessors": [{"componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                    {"componentType": 5123, "count": 3, "type": "SCALAR"}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "extensions":
        {"EXT_other_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}}}]}],
      "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]})";
    for (const auto& [name, json, ext] : {std::tuple{"other_req.gltf", other_json, "EXT_other_mesh_compression"}}) {
        const std::string path = write_file(name, json);
        const std::string err = error_text([&] { load_scene(path); });
        EXPECT_NE(err.find(path + ": /extensionsRequired/0: required extension " + std::string(ext) +
                           " is not supported by whitted"),
                  std::string::npos)
            << err;
        // The same JSON as a GLB's JSON chunk.
        const std::string glb_path = write_file(std::string(name) + ".glb", make_glb(json));
        const std::string glb_err = error_text([&] { load_scene(glb_path); });
        EXPECT_NE(glb_err.find("/extensionsRequired/0: required extension " + std::string(ext)), std::string::npos)
            << glb_err;
    }
}

// EXT_meshopt_compression: a quad whose positions (ATTRIBUTES, EXPONENTIAL filter) and indices
// (TRIANGLES) are meshopt streams in buffer 1, decoded into fallback buffer 0 (no uri); as .gltf
// and as GLB; a corrupt stream and a hostile count are located errors.
TEST(GltfHandMade, MeshoptStreamsDecodeIntoTheFallbackBuffer) {
    const std::vector<float> positions{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0.25f};
    const std::vector<unsigned> indices{0, 1, 2, 0, 2, 3};
    std::vector<uint8_t> exp_encoded(positions.size() * 4);
    meshopt_encodeFilterExp(exp_encoded.data(), 4, 12, 24, positions.data());
    std::vector<uint8_t> vstream(meshopt_encodeVertexBufferBound(4, 12));
    vstream.resize(meshopt_encodeVertexBuffer(vstream.data(), vstream.size(), exp_encoded.data(), 4, 12));
    std::vector<uint8_t> istream(meshopt_encodeIndexBufferBound(6, 4));
    istream.resize(meshopt_encodeIndexBuffer(istream.data(), istream.size(), indices.data(), 6));
    std::vector<uint8_t> compressed = vstream;
    while (compressed.size() % 4) compressed.push_back(0);
    const size_t ioffset = compressed.size();
    compressed.insert(compressed.end(), istream.begin(), istream.end());
    // In a .gltf: buffer 0 the fallback, buffer 1 the streams (a data URI). In a GLB, as gltfpack
    // writes them: buffer 0 the BIN chunk with the streams, buffer 1 the fallback.
    auto json_with = [&](size_t count, const std::vector<uint8_t>& stream, bool glb) {
        const std::string fallback = R"({"byteLength": 60, "extensions": {"EXT_meshopt_compression": {"fallback": true}}})";
        const std::string data = glb ? fmt::format(R"({{"byteLength": {}}})", stream.size())
                                     : fmt::format(R"({{"byteLength": {}, "uri": "{}"}})", stream.size(), data_uri(stream));
        const int target = glb ? 1 : 0, source = glb ? 0 : 1;
        return fmt::format(R"({{"asset": {{"version": "2.0"}},
      "extensionsUsed": ["EXT_meshopt_compression"], "extensionsRequired": ["EXT_meshopt_compression"],
      "buffers": [{}, {}],
      "bufferViews": [{{"buffer": {}, "byteLength": 48, "byteStride": 12, "extensions": {{"EXT_meshopt_compression":
                         {{"buffer": {}, "byteLength": {}, "byteStride": 12, "count": {}, "mode": "ATTRIBUTES", "filter": "EXPONENTIAL"}}}}}},
                      {{"buffer": {}, "byteOffset": 48, "byteLength": 12, "extensions": {{"EXT_meshopt_compression":
                         {{"buffer": {}, "byteOffset": {}, "byteLength": {}, "byteStride": 2, "count": 6, "mode": "TRIANGLES"}}}}}}],
      "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0.25]}},
                    {{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}}],
      "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
      "nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}]}})",
                           glb ? data : fallback, glb ? fallback : data, target, source, vstream.size(), count, target,
                           source, ioffset, istream.size());
    };
    auto check = [&](const Scene& s) {
        ASSERT_EQ(s.meshes.size(), 1u);
        const Mesh& m = s.meshes[0];
        ASSERT_EQ(m.positions.size(), 4u);
        for (size_t v = 0; v < 4; ++v)
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.positions[v][c], positions[3 * v + size_t(c)], 1e-6f);
        ASSERT_EQ(m.indices.size(), 6u);
        for (size_t k = 0; k < 6; ++k) EXPECT_EQ(m.indices[k], indices[k]);
    };
    const Scene plain = load_scene(write_file("meshopt.gltf", json_with(4, compressed, false)));
    check(plain);
    // `whitted info`'s record: both views' streams against their decoded 48 + 12 bytes.
    ASSERT_EQ(plain.compressed.size(), 1u);
    EXPECT_EQ(plain.compressed[0].codec, "meshopt");
    EXPECT_EQ(plain.compressed[0].compressed_bytes, vstream.size() + istream.size());
    EXPECT_EQ(plain.compressed[0].decoded_bytes, 60u);
    // The same as a GLB (its JSON chunk rewritten; the chunk after it kept).
    check(load_scene(write_file("meshopt.glb", make_glb(json_with(4, compressed, true), compressed))));

    std::vector<uint8_t> corrupt = compressed;
    for (size_t i = 1; i < vstream.size(); ++i) corrupt[i] = 0xFF;
    const std::string err = error_text([&] { load_scene(write_file("meshopt_corrupt.gltf", json_with(4, corrupt, false))); });
    EXPECT_NE(err.find("/bufferViews/0/extensions/EXT_meshopt_compression: corrupt ATTRIBUTES stream"),
              std::string::npos)
        << err;
    const std::string huge = error_text([&] { load_scene(write_file("meshopt_huge.gltf", json_with(1000000000, compressed, false))); });
    EXPECT_NE(huge.find("/bufferViews/0/extensions/EXT_meshopt_compression: count 1000000000 x byteStride 12"),
              std::string::npos)
        << huge;
}

TEST(GltfHandMade, ByteStrideOutOfRange) {
    // tinygltf refuses it while parsing (whitted's own check covers views tinygltf lets through).
    const std::string path = write_gltf("stride300.gltf",
                                        edit(kQuadJson, R"("byteOffset": 48, "byteLength": 12})",
                                             R"("byteOffset": 48, "byteLength": 12, "byteStride": 300})"),
                                        quad_bin());
    const std::string err = error_text([&] { load_scene(path); });
    EXPECT_NE(err.find(path + ": a bufferView byteStride is not a multiple of 4 in [4, 252]"), std::string::npos)
        << err;
    EXPECT_NE(err.find("300"), std::string::npos) << err;
}

TEST(GltfHandMade, SparseIndexOutOfRange) {
    Bytes b = quad_bin();
    b.put<uint16_t>({7, 0});  // sparse index 7 >= count 4 (+ padding)
    b.put<float>({9, 9, 9});  // sparse value
    const std::string json =
        edit(edit(kQuadJson, R"({"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"})",
                  R"({"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "sparse": {"count": 1,
                 "indices": {"bufferView": 2, "componentType": 5123}, "values": {"bufferView": 3}}})"),
             R"({"buffer": 0, "byteOffset": 48, "byteLength": 12}])",
             R"({"buffer": 0, "byteOffset": 48, "byteLength": 12}, {"buffer": 0, "byteOffset": 60, "byteLength": 2},
           {"buffer": 0, "byteOffset": 64, "byteLength": 12}])");
    const std::string err = error_text([&] { load_scene(write_gltf("sparse_oob.gltf", json, b)); });
    EXPECT_NE(err.find("/accessors/0/sparse/indices: sparse index 7"), std::string::npos) << err;
}

TEST(GltfHandMade, IndexValueOutOfRange) {
    Bytes b;
    b.put<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
    b.put<uint16_t>({0, 1, 2, 0, 2, 4});
    const std::string err = error_text([&] { load_scene(write_gltf("index_oob.gltf", kQuadJson, b)); });
    EXPECT_NE(err.find("/meshes/0/primitives/0/indices: index value 4 is not less than the vertex count 4"),
              std::string::npos)
        << err;
}

TEST(GltfHandMade, AllDegenerateMeshLoads) {
    Bytes b;
    b.put<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
    b.put<uint16_t>({0, 0, 0, 1, 1, 1});
    const Scene s = load_scene(write_gltf("degenerate.gltf", kQuadJson, b));
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(s.meshes[0].triangle_count(), 2u);
    for (const Vec3f& n : s.meshes[0].normals) EXPECT_NEAR(length(n), 1.f, 1e-6f);  // no NaN
}

TEST(GltfHandMade, TrianglesCountNotMultipleOfThreeDropsTheRest) {
    Bytes b;
    b.put<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
    b.put<uint16_t>({0, 1, 2, 0, 0, 0});
    const std::string json =
        edit(kQuadJson, R"("componentType": 5123, "count": 6)", R"("componentType": 5123, "count": 4)");
    const Scene s = load_scene(write_gltf("count4.gltf", json, b));
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(s.meshes[0].triangle_count(), 1u);
    EXPECT_TRUE(has_warning(s, "not a multiple of 3"));
}

TEST(GltfHandMade, QuantizedAttributes) {
    // KHR_mesh_quantization: normalized SHORT positions, normalized UNSIGNED_BYTE texcoords,
    // normalized UNSIGNED_SHORT VEC3 colors, normalized BYTE normals.
    Bytes b;
    b.put<int16_t>({0, 0, 0, 0, 32767, 0, 0, 0, 32767, 32767, 0, 0, -32768, 32767, 0, 0});  // 4 x (VEC3 + pad)
    b.put<uint8_t>({0, 0, 255, 0, 255, 255, 128, 255});                                     // 4 x VEC2
    b.put<uint16_t>({65535, 0, 0, 0, 65535, 0, 0, 0, 65535, 32768, 32768, 32768});          // 4 x VEC3
    b.put<int8_t>({0, 0, 127, 0, 0, 0, 127, 0, 0, 0, -128, 0, 0, 0, 127, 0});               // 4 x (VEC3 + pad)
    b.put<uint16_t>({0, 1, 2, 0, 2, 3});
    const std::string json = R"({
      "asset": {"version": "2.0"},
      "extensionsUsed": ["KHR_mesh_quantization"], "extensionsRequired": ["KHR_mesh_quantization"],
      "buffers": [{"uri": "$BUFFER", "byteLength": $LENGTH}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 32, "byteStride": 8},
                      {"buffer": 0, "byteOffset": 32, "byteLength": 8},
                      {"buffer": 0, "byteOffset": 40, "byteLength": 24},
                      {"buffer": 0, "byteOffset": 64, "byteLength": 16, "byteStride": 4},
                      {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
      "accessors": [{"bufferView": 0, "componentType": 5122, "normalized": true, "count": 4, "type": "VEC3"},
                    {"bufferView": 1, "componentType": 5121, "normalized": true, "count": 4, "type": "VEC2"},
                    {"bufferView": 2, "componentType": 5123, "normalized": true, "count": 4, "type": "VEC3"},
                    {"bufferView": 3, "componentType": 5120, "normalized": true, "count": 4, "type": "VEC3"},
                    {"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "COLOR_0": 2, "NORMAL": 3}, "indices": 4}]}],
      "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]
    })";
    const Scene s = load_scene(write_gltf("quantized.gltf", json, b));
    const Mesh& m = s.meshes.at(0);
    EXPECT_EQ(m.positions[1], Vec3f(1.f, 0.f, 0.f));
    EXPECT_EQ(m.positions[3], Vec3f(-1.f, 1.f, 0.f));  // -32768 clamps to -1
    EXPECT_EQ(m.uv0[1], Vec2f(1.f, 0.f));
    EXPECT_NEAR(m.uv0[3].x, 128.f / 255.f, 1e-7f);
    EXPECT_EQ(m.colors[0], Vec4f(1.f, 0.f, 0.f, 1.f));
    EXPECT_NEAR(m.colors[3].x, 32768.f / 65535.f, 1e-7f);
    EXPECT_EQ(m.normals[0], Vec3f(0.f, 0.f, 1.f));
    EXPECT_EQ(m.normals[2], Vec3f(0.f, 0.f, -1.f));
    EXPECT_EQ(extension(s, "KHR_mesh_quantization")->support, ExtensionSupport::Supported);
}

TEST(GltfHandMade, ZeroNormalsAreReplaced) {
    Bytes b = quad_bin();
    b.put<float>({0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 1});  // vertex 1 has a zero normal
    const std::string json = edit(
        edit(kQuadJson, R"("attributes": {"POSITION": 0})", R"("attributes": {"POSITION": 0, "NORMAL": 2})"),
        R"({"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}])",
        R"({"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}, {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC3"}])");
    const std::string json2 = edit(
        json, R"({"buffer": 0, "byteOffset": 48, "byteLength": 12}])",
        R"({"buffer": 0, "byteOffset": 48, "byteLength": 12}, {"buffer": 0, "byteOffset": 60, "byteLength": 48}])");
    const Scene s = load_scene(write_gltf("zero_normal.gltf", json2, b));
    EXPECT_EQ(s.meshes[0].normals[1], Vec3f(0.f, 0.f, 1.f));
    EXPECT_TRUE(has_warning(s, "zero or non-finite normals replaced"));
}

/// The quad with TEXCOORD_0 (u along +x, glTF v down: v = 1 - y) and a normal-mapped material
/// whose texture is a 1x1 PNG data URI.
std::string normal_mapped_quad(const std::string& name) {
    Bytes b = quad_bin();
    b.put<float>({0, 1, 1, 1, 1, 0, 0, 0});
    const std::vector<uint8_t> png = make_png(1, 1, 8, 6, {128, 128, 255, 255});
    std::string json = edit(kQuadJson, R"("attributes": {"POSITION": 0})",
                            R"("attributes": {"POSITION": 0, "TEXCOORD_0": 2}, "material": 0)");
    json = edit(
        json, R"({"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}])",
        R"({"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}, {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}])");
    json = edit(
        json, R"({"buffer": 0, "byteOffset": 48, "byteLength": 12}])",
        R"({"buffer": 0, "byteOffset": 48, "byteLength": 12}, {"buffer": 0, "byteOffset": 60, "byteLength": 32}])");
    json = edit(json, R"("scene": 0)",
                R"("scene": 0, "materials": [{"normalTexture": {"index": 0, "scale": 0.5}}],
        "textures": [{"source": 0}], "images": [{"uri": ")" +
                    data_uri(png, "image/png") + R"("}])");
    return write_gltf(name, json, b);
}

TEST(GltfHandMade, TangentsGeneratedForNormalTextures) {
    const Scene s = load_scene(normal_mapped_quad("normal_mapped.gltf"));
    const Mesh& m = s.meshes.at(0);
    ASSERT_EQ(m.tangents.size(), 4u);
    for (const Vec4f& t : m.tangents) {
        EXPECT_NEAR(t.x, 1.f, 1e-6f);  // dP/du = +X
        EXPECT_NEAR(t.y, 0.f, 1e-6f);
        EXPECT_EQ(t.w, 1.f);  // cross(N, T) = +Y = image up (v decreasing)
    }
    EXPECT_FLOAT_EQ(s.materials[0].normal_texture.scale, 0.5f);
    ASSERT_EQ(s.textures.size(), 1u);
    EXPECT_FALSE(s.textures[0].srgb);
    EXPECT_EQ(s.textures[0].levels.at(0).texels, (std::vector<uint8_t>{128, 128, 255, 255}));
}

TEST(GltfHandMade, PngChannelExpansionAndSixteenBit) {
    // 2x1 16-bit grayscale PNG (big-endian samples 0xFFFF, 0x8080) -> RGBA8 (255.., 128..).
    const std::vector<uint8_t> png = make_png(2, 1, 16, 0, {0xFF, 0xFF, 0x80, 0x80});
    std::string json =
        edit(kQuadJson, R"("attributes": {"POSITION": 0})", R"("attributes": {"POSITION": 0}, "material": 0)");
    json = edit(json, R"("scene": 0)",
                R"("scene": 0, "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0, "sampler": 0}], "samplers": [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33648}],
        "images": [{"uri": ")" +
                    data_uri(png, "image/png") + R"("}])");
    const Scene s = load_scene(write_gltf("gray16.gltf", json, quad_bin()));
    ASSERT_EQ(s.textures.size(), 1u);
    const Texture& t = s.textures[0];
    EXPECT_TRUE(t.srgb);
    EXPECT_EQ(t.mag_filter, FilterMode::Nearest);
    EXPECT_EQ(t.min_filter, FilterMode::Nearest);
    EXPECT_FALSE(t.use_mips);
    EXPECT_EQ(t.levels.size(), 1u);
    EXPECT_EQ(t.wrap_s, WrapMode::MirroredRepeat);
    EXPECT_EQ(t.levels.at(0).texels, (std::vector<uint8_t>{255, 255, 255, 255, 128, 128, 128, 255}));
}

// EXT_texture_webp: the WebP image is preferred over the core (PNG) fallback; lossless decodes
// exactly, lossy within its quantisation; a corrupt one is a located error; a texture that offers
// only KHR_texture_basisu is dropped with one warning naming it.
TEST(GltfHandMade, WebpTexturesDecodeAndArePreferred) {
    const int w = 4, h = 2;
    std::vector<uint8_t> rgba(size_t(w * h * 4));
    for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = uint8_t((i * 37 + 11) % 256);
    for (size_t i = 3; i < rgba.size(); i += 4) rgba[i] = 255;
    uint8_t* lossless = nullptr;
    const size_t lossless_size = WebPEncodeLosslessRGBA(rgba.data(), w, h, w * 4, &lossless);
    // Lossy: a smooth 16x16 gradient (lossy WebP subsamples chroma, so not the noisy image).
    const int lw = 16;
    std::vector<uint8_t> smooth(size_t(lw * lw * 4));
    for (int y = 0; y < lw; ++y)
        for (int x = 0; x < lw; ++x) {
            uint8_t* p = &smooth[size_t((y * lw + x) * 4)];
            p[0] = uint8_t(40 + 10 * x);
            p[1] = uint8_t(200 - 8 * y);
            p[2] = uint8_t(100 + 4 * (x + y));
            p[3] = 255;
        }
    uint8_t* lossy = nullptr;
    const size_t lossy_size = WebPEncodeRGBA(smooth.data(), lw, lw, lw * 4, 95.f, &lossy);
    ASSERT_GT(lossless_size, 0u);
    ASSERT_GT(lossy_size, 0u);
    const std::vector<uint8_t> webp_exact(lossless, lossless + lossless_size), webp_lossy(lossy, lossy + lossy_size);
    WebPFree(lossless);
    WebPFree(lossy);
    const std::vector<uint8_t> fallback = make_png(1, 1, 8, 6, {1, 2, 3, 255});  // must not be used
    // tinygltf takes no image/webp data URIs: an external file, as real files have, or octet-stream.
    auto scene_with = [&](const std::string& name, const std::vector<uint8_t>& webp) {
        const std::string uri = name + ".webp";
        write_file(uri, webp);
        std::string json =
            edit(kQuadJson, R"("attributes": {"POSITION": 0})", R"("attributes": {"POSITION": 0}, "material": 0)");
        json = edit(json, R"("scene": 0)",
                    R"("scene": 0, "extensionsUsed": ["EXT_texture_webp"],
            "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
            "textures": [{"source": 0, "extensions": {"EXT_texture_webp": {"source": 1}}}],
            "images": [{"uri": ")" + data_uri(fallback, "image/png") + R"("}, {"uri": ")" + uri +
                        R"(", "mimeType": "image/webp"}])");
        return write_gltf(name, json, quad_bin());
    };
    const Scene exact = load_scene(scene_with("webp_lossless.gltf", webp_exact));
    ASSERT_EQ(exact.textures.size(), 1u);
    EXPECT_EQ(exact.textures[0].image, 1);
    ASSERT_FALSE(exact.textures[0].levels.empty());
    EXPECT_EQ(exact.textures[0].levels[0].width, w);
    EXPECT_EQ(exact.textures[0].levels[0].texels, rgba);
    ASSERT_EQ(exact.extensions.size(), 1u);
    EXPECT_EQ(exact.extensions[0].support, ExtensionSupport::Supported);
    const Scene near = load_scene(scene_with("webp_lossy.gltf", webp_lossy));
    const std::vector<uint8_t>& got = near.textures.at(0).levels.at(0).texels;
    ASSERT_EQ(got.size(), smooth.size());
    int worst = 0;
    for (size_t i = 0; i < got.size(); ++i) worst = std::max(worst, std::abs(int(got[i]) - int(smooth[i])));
    EXPECT_LE(worst, 12);  // quality 95 on a smooth image

    std::vector<uint8_t> broken = webp_exact;
    for (size_t i = 20; i < broken.size(); ++i) broken[i] = uint8_t(broken[i] ^ 0x5A);
    const std::string err = error_text([&] { load_scene(scene_with("webp_broken.gltf", broken)); });
    EXPECT_NE(err.find("/images/1: cannot decode image"), std::string::npos) << err;

    std::string ktx = edit(kQuadJson, R"("attributes": {"POSITION": 0})",
                           R"("attributes": {"POSITION": 0}, "material": 0)");
    ktx = edit(ktx, R"("scene": 0)", R"("scene": 0, "extensionsUsed": ["KHR_texture_basisu"],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"extensions": {"KHR_texture_basisu": {"source": 0}}}],
        "images": [{"uri": "tex.ktx2", "mimeType": "image/ktx2"}])");
    write_file("tex.ktx2", std::string("\xABKTX 20\xBB\r\n\x1A\n"));
    const Scene k = load_scene(write_gltf("ktx_only.gltf", ktx, quad_bin()));
    EXPECT_TRUE(k.textures.empty());
    EXPECT_EQ(warnings_containing(k, "/textures/0: no image whitted decodes (PNG, JPEG, WebP) - only KHR_texture_basisu"),
              1u);
}

TEST(GltfHandMade, UndecodableImageIsAnError) {
    std::string json = edit(kQuadJson, R"("scene": 0)",
                            R"("scene": 0, "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}], "images": [{"uri": "garbage.png"}])");
    const std::string path = write_gltf("bad_image.gltf", json, quad_bin());
    write_file("garbage.png", std::string("this is not a png"));
    const std::string err = error_text([&] { load_scene(path); });
    EXPECT_NE(err.find("/images/0: cannot decode image 'garbage.png'"), std::string::npos) << err;
    // Without decoding the file only has to exist.
    EXPECT_NO_THROW(load_scene(path, no_textures()));
}

// Images are decoded in parallel (when there is enough to decode: these two are 200 KB each);
// with two bad ones the error is still the one the textures' order meets first (the base color
// texture, whose image is the second), every time.
TEST(GltfHandMade, FirstUndecodableImageInTextureOrderIsTheError) {
    std::string json = edit(kQuadJson, R"("scene": 0)",
                            R"("scene": 0, "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
            "metallicRoughnessTexture": {"index": 1}}}],
        "textures": [{"source": 1}, {"source": 0}], "images": [{"uri": "first.png"}, {"uri": "second.png"}])");
    json = edit(json, R"("attributes": {"POSITION": 0})", R"("attributes": {"POSITION": 0}, "material": 0)");
    const std::string path = write_gltf("two_bad_images.gltf", json, quad_bin());
    write_file("first.png", "not a png either" + std::string(200000, 'x'));
    write_file("second.png", "this is not a png" + std::string(200000, 'y'));
    for (int i = 0; i < 20; ++i) {
        const std::string err = error_text([&] { load_scene(path); });
        ASSERT_NE(err.find("/images/1: cannot decode image 'second.png'"), std::string::npos) << i << ": " << err;
    }
}

TEST(GltfHandMade, MissingImageIsAnErrorEvenWithoutDecoding) {
    std::string json = edit(kQuadJson, R"("scene": 0)", R"("scene": 0, "images": [{"uri": "nowhere.png"}])");
    const std::string path = write_gltf("missing_image.gltf", json, quad_bin());
    const std::string err = error_text([&] { load_scene(path, no_textures()); });
    EXPECT_NE(err.find("/images/0/uri: image file 'nowhere.png' not found"), std::string::npos) << err;
}

TEST(GltfHandMade, SpotAndDirectionalLights) {
    // Spot at (1, 2, 3) rotated -90 degrees about X (-Z turns to -Y); directional unrotated.
    std::string json = edit(kQuadJson, R"("nodes": [{"mesh": 0}])",
                            R"("nodes": [{"mesh": 0},
          {"translation": [1, 2, 3], "rotation": [-0.7071067811865476, 0, 0, 0.7071067811865476],
           "extensions": {"KHR_lights_punctual": {"light": 0}}},
          {"extensions": {"KHR_lights_punctual": {"light": 1}}}])");
    json = edit(json, R"("nodes": [0])", R"("nodes": [0, 1, 2])");
    json = edit(json, R"("scene": 0)", R"("scene": 0, "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
          {"type": "spot", "color": [1, 0.5, 0.25], "intensity": 40, "range": 10,
           "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}},
          {"type": "directional", "intensity": 2.5, "name": "sun"}]}})");
    const Scene s = load_scene(write_gltf("lights.gltf", json, quad_bin()));
    ASSERT_EQ(s.lights.size(), 2u);
    const Light& spot = s.lights[0];
    EXPECT_EQ(spot.type, LightType::Spot);
    EXPECT_EQ(spot.color, Color(1.f, 0.5f, 0.25f));
    EXPECT_FLOAT_EQ(spot.intensity, 40.f);
    EXPECT_FLOAT_EQ(spot.range, 10.f);
    EXPECT_FLOAT_EQ(spot.inner_cone, 0.2f);
    EXPECT_FLOAT_EQ(spot.outer_cone, 0.6f);
    EXPECT_VEC3_NEAR(spot.position, 1.0, 2.0, 3.0, 1e-12);
    EXPECT_VEC3_NEAR(spot.direction, 0.0, -1.0, 0.0, 1e-12);
    const Light& sun = s.lights[1];
    EXPECT_EQ(sun.name, "sun");
    EXPECT_EQ(sun.type, LightType::Directional);
    EXPECT_EQ(sun.attenuation, Attenuation::None);
    EXPECT_VEC3_NEAR(sun.direction, 0.0, 0.0, -1.0, 0);
    EXPECT_FALSE(has_warning(s, "default light"));
}

TEST(GltfHandMade, InvalidCameraAndLightValues) {
    std::string json = edit(kQuadJson, R"({"mesh": 0})", R"({"mesh": 0, "camera": 0})");
    json = edit(json, R"("scene": 0)",
                R"("scene": 0, "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0}}])");
    EXPECT_NE(error_text([&] {
                  load_scene(write_gltf("znear0.gltf", json, quad_bin()));
              }).find("/cameras/0/perspective/znear"),
              std::string::npos);
    json = edit(kQuadJson, R"("scene": 0)", R"("scene": 0, "extensions": {"KHR_lights_punctual": {"lights": [
          {"type": "spot", "spot": {"innerConeAngle": 0.8, "outerConeAngle": 0.6}}]}})");
    EXPECT_NE(error_text([&] {
                  load_scene(write_gltf("cones.gltf", json, quad_bin()));
              }).find("/extensions/KHR_lights_punctual/lights/0/spot"),
              std::string::npos);
}

TEST(GltfHandMade, MirroredGpuInstanceGetsMirroredMesh) {
    Bytes b = quad_bin();
    b.put<float>({1, 1, 1, -1, 1, 1});  // SCALE of two instances
    std::string json =
        edit(kQuadJson, R"("nodes": [{"mesh": 0}])",
             R"("nodes": [{"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"SCALE": 2}}}}])");
    json = edit(
        json, R"({"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}])",
        R"({"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}, {"bufferView": 2, "componentType": 5126, "count": 2, "type": "VEC3"}])");
    json = edit(
        json, R"({"buffer": 0, "byteOffset": 48, "byteLength": 12}])",
        R"({"buffer": 0, "byteOffset": 48, "byteLength": 12}, {"buffer": 0, "byteOffset": 60, "byteLength": 24}])");
    const Scene s = load_scene(write_gltf("instanced_mirror.gltf", json, b));
    ASSERT_EQ(s.instances.size(), 2u);
    ASSERT_EQ(s.meshes.size(), 2u);
    EXPECT_EQ(s.meshes[s.instances[1].mesh].indices, (std::vector<uint32_t>{0, 2, 1, 0, 3, 2}));
    EXPECT_EQ(s.instances[1].world_from_object(0, 0), -1.0);
}

// Skins and morph targets are applied, not ignored (tests/unit/test_gltf_animation.cpp poses them):
// this quad's skin has no JOINTS/WEIGHTS to read and its morph weights default to 0, so it keeps its
// shape; the file's skin and morphed mesh are recorded.
TEST(GltfHandMade, SkinsAndMorphTargetsAreRecordedNotIgnored) {
    Bytes b = quad_bin();
    std::string json = edit(kQuadJson, R"("attributes": {"POSITION": 0}, "indices": 1})",
                            R"("attributes": {"POSITION": 0}, "indices": 1, "targets": [{"POSITION": 0}]})");
    json = edit(json, R"("nodes": [{"mesh": 0}])",
                R"("nodes": [{"mesh": 0, "skin": 0}], "skins": [{"joints": [0], "inverseBindMatrices": 2}])");
    json = edit(
        json, R"({"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}])",
        R"({"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}, {"componentType": 5126, "count": 1, "type": "MAT4"}])");
    const Scene s = load_scene(write_gltf("skinned.gltf", json, b));
    EXPECT_EQ(warnings_containing(s, "ignored"), 0u);
    EXPECT_EQ(s.instanced_triangle_count(), 2u);
    ASSERT_EQ(s.skins.size(), 1u);
    EXPECT_EQ(s.skins[0].joints, 1u);
    ASSERT_EQ(s.morphs.size(), 1u);
    EXPECT_EQ(s.morphs[0].targets, 1u);
    EXPECT_EQ(s.meshes[0].positions[2], Vec3f(1, 1, 0));  // vertex 2 as stored: weight 0
}

TEST(GltfHandMade, GltfOneVersionAndNoSceneFile) {
    const std::string v1 =
        write_gltf("v1.gltf", edit(kQuadJson, R"("version": "2.0")", R"("version": "1.0")"), quad_bin());
    EXPECT_NE(error_text([&] { load_scene(v1); }).find("/asset/version"), std::string::npos);
    // No "scenes": every root node is shown, with a warning.
    const std::string json = edit(kQuadJson, "\"scenes\": [{\"nodes\": [0]}],\n  \"scene\": 0", "\"extras\": {}");
    const Scene s = load_scene(write_gltf("no_scene.gltf", json, quad_bin()));
    EXPECT_EQ(s.instances.size(), 1u);
    EXPECT_TRUE(has_warning(s, "no scene"));
}

}  // namespace
}  // namespace whitted::test
