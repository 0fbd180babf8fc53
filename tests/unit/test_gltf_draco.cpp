// KHR_draco_mesh_compression: streams made here with libdraco's encoder, in hand-made glTF files.

#include <algorithm>
#include <array>
#include <string>
#include <tuple>
#include <vector>

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "importers/scene_report.h"
#include "tests/support/test_importer_util.h"

namespace whitted::test {
namespace {

// Two quads folded along x = 1 (4 triangles, 6 corners each shared), with every attribute kind
// the extension maps: normal, texcoord, colour, tangent and a generic one (not rendered).
constexpr int kVerts = 6;
const std::array<float, 3 * kVerts> kPos{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 0, 0.5f, 2, 1, 0.5f};
const std::array<float, 2 * kVerts> kUv{0, 0, 0.5f, 0, 0.5f, 1, 0, 1, 1, 0, 1, 1};
const std::array<float, 4 * kVerts> kColor{1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 0, 1, 0, 1, 1, 1, 1, 0, 1, 1};
const std::array<uint32_t, 12> kTris{0, 1, 2, 0, 2, 3, 1, 4, 5, 1, 5, 2};

struct Stream {
    std::vector<uint8_t> bytes;
    size_t points = 0, faces = 0;
};

/// The mesh encoded losslessly (no quantization) or with `position_bits` of position quantization.
Stream encode(int position_bits) {
    draco::Mesh mesh;
    mesh.set_num_points(kVerts);
    auto add = [&](draco::GeometryAttribute::Type type, int components, const float* values) {
        draco::GeometryAttribute ga;
        ga.Init(type, nullptr, uint8_t(components), draco::DT_FLOAT32, false, int64_t(sizeof(float)) * components, 0);
        const int id = mesh.AddAttribute(ga, true, kVerts);
        for (int v = 0; v < kVerts; ++v)
            mesh.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(v), values + components * v);
        return id;
    };
    std::vector<float> normals, tangents, generic;
    for (int v = 0; v < kVerts; ++v) {
        normals.insert(normals.end(), {0, 0, 1});
        tangents.insert(tangents.end(), {1, 0, 0, 1});
        generic.push_back(float(v) * 10);
    }
    add(draco::GeometryAttribute::POSITION, 3, kPos.data());      // id 0
    add(draco::GeometryAttribute::NORMAL, 3, normals.data());     // id 1
    add(draco::GeometryAttribute::TEX_COORD, 2, kUv.data());      // id 2
    add(draco::GeometryAttribute::COLOR, 4, kColor.data());       // id 3
    add(draco::GeometryAttribute::GENERIC, 4, tangents.data());   // id 4 (TANGENT)
    add(draco::GeometryAttribute::GENERIC, 1, generic.data());    // id 5 (_TEMPERATURE)
    for (size_t t = 0; t < kTris.size(); t += 3)
        mesh.AddFace({draco::PointIndex(kTris[t]), draco::PointIndex(kTris[t + 1]), draco::PointIndex(kTris[t + 2])});
    draco::Encoder encoder;
    if (position_bits > 0) encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, position_bits);
    draco::EncoderBuffer out;
    EXPECT_TRUE(encoder.EncodeMeshToBuffer(mesh, &out).ok());
    Stream s;
    s.bytes.assign(out.data(), out.data() + out.size());
    // The counts the accessors must declare: what the stream decodes to (the encoder may reorder).
    draco::DecoderBuffer in;
    in.Init(out.data(), out.size());
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&in);
    EXPECT_TRUE(decoded.ok());
    s.points = decoded.value()->num_points();
    s.faces = decoded.value()->num_faces();
    return s;
}

/// A glTF file whose one primitive is the Draco stream (in a data URI, or for a GLB in BIN).
std::string draco_json(const Stream& s, bool glb, size_t position_count = 0, const std::string& extra_attribute = "") {
    const std::string buffer = glb ? fmt::format(R"({{"byteLength": {}}})", s.bytes.size())
                                   : fmt::format(R"({{"byteLength": {}, "uri": "{}"}})", s.bytes.size(), data_uri(s.bytes));
    const size_t n = s.points;
    return fmt::format(R"({{"asset": {{"version": "2.0"}},
      "extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"],
      "buffers": [{}], "bufferViews": [{{"buffer": 0, "byteLength": {}}}],
      "accessors": [{{"componentType": 5126, "count": {}, "type": "VEC3", "min": [0, 0, 0], "max": [2, 1, 0.5]}},
                    {{"componentType": 5126, "count": {}, "type": "VEC3"}},
                    {{"componentType": 5126, "count": {}, "type": "VEC2"}},
                    {{"componentType": 5126, "count": {}, "type": "VEC4"}},
                    {{"componentType": 5126, "count": {}, "type": "VEC4"}},
                    {{"componentType": 5126, "count": {}, "type": "SCALAR"}},
                    {{"componentType": 5123, "count": {}, "type": "SCALAR"}}],
      "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "COLOR_0": 3,
                    "TANGENT": 4, "_TEMPERATURE": 5}}, "indices": 6, "extensions": {{"KHR_draco_mesh_compression":
                    {{"bufferView": 0, "attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "COLOR_0": 3,
                    "TANGENT": 4, "_TEMPERATURE": 5{}}}}}}}}}]}}],
      "nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}]}})",
                       buffer, s.bytes.size(), position_count ? position_count : n, n, n, n, n, n, s.faces * 3,
                       extra_attribute);
}

/// Each triangle as its corners' (position, uv, colour), rotated to start at its smallest corner
/// and sorted: the same for any vertex order the encoder chose.
using Corner = std::array<float, 9>;
std::vector<std::array<Corner, 3>> triangles(const std::vector<Corner>& vertex, const std::vector<uint32_t>& idx) {
    std::vector<std::array<Corner, 3>> out;
    for (size_t t = 0; t + 2 < idx.size(); t += 3) {
        std::array<Corner, 3> tri{vertex[idx[t]], vertex[idx[t + 1]], vertex[idx[t + 2]]};
        std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
        out.push_back(tri);
    }
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<std::array<Corner, 3>> original_triangles() {
    std::vector<Corner> v(kVerts);
    for (int i = 0; i < kVerts; ++i)
        v[size_t(i)] = {kPos[3 * i], kPos[3 * i + 1], kPos[3 * i + 2], kUv[2 * i], kUv[2 * i + 1],
                        kColor[4 * i], kColor[4 * i + 1], kColor[4 * i + 2], kColor[4 * i + 3]};
    return triangles(v, std::vector<uint32_t>(kTris.begin(), kTris.end()));
}

std::vector<std::array<Corner, 3>> scene_triangles(const Mesh& m) {
    std::vector<Corner> v(m.positions.size());
    for (size_t i = 0; i < v.size(); ++i) {
        const Vec3f p = m.positions[i];
        const Vec2f uv = m.uv0.at(i);
        const Vec4f c = m.colors.at(i);
        v[i] = {p.x, p.y, p.z, uv.x, uv.y, c.x, c.y, c.z, c.w};
    }
    return triangles(v, m.indices);
}

TEST(GltfDraco, EveryAttributeAndTheIndicesDecode) {
    const Stream s = encode(0);
    for (const bool glb : {false, true}) {
        SCOPED_TRACE(glb ? "glb" : "gltf");
        const std::string json = draco_json(s, glb);
        const std::string path = glb ? write_file("draco.glb", make_glb(json, s.bytes))
                                     : write_file("draco.gltf", json);
        const Scene scene = load_scene(path);
        ASSERT_EQ(scene.meshes.size(), 1u);
        const Mesh& m = scene.meshes[0];
        EXPECT_EQ(m.triangle_count(), 4u);
        EXPECT_EQ(scene_triangles(m), original_triangles());  // lossless: exactly the same
        ASSERT_EQ(m.tangents.size(), m.positions.size());
        for (const Vec4f& t : m.tangents) EXPECT_EQ(t, Vec4f(1, 0, 0, 1));
        for (const Vec3f& n : m.normals) EXPECT_EQ(n, Vec3f(0, 0, 1));
        ASSERT_EQ(scene.compressed.size(), 1u);
        EXPECT_EQ(scene.compressed[0].pointer, "/meshes/0/primitives/0");
        EXPECT_EQ(scene.compressed[0].codec, "draco");
        EXPECT_EQ(scene.compressed[0].compressed_bytes, s.bytes.size());
        // 6 attributes (3+3+2+4+4+1 floats per point) and 12 uint16 indices.
        EXPECT_EQ(scene.compressed[0].decoded_bytes, s.points * 17 * 4 + s.faces * 3 * 2);
        EXPECT_NE(describe_scene(scene).find(fmt::format(
                      "compressed: primitive=/meshes/0/primitives/0 codec=draco compressed_bytes={} decoded_bytes={} ratio=",
                      s.bytes.size(), s.points * 17 * 4 + s.faces * 3 * 2)),
                  std::string::npos);
    }
}

TEST(GltfDraco, QuantizedPositionsStayWithinTheirStep) {
    const Stream s = encode(11);
    const Scene scene = load_scene(write_file("draco_q11.gltf", draco_json(s, false)));
    ASSERT_EQ(scene.meshes.size(), 1u);
    const auto got = scene_triangles(scene.meshes[0]), want = original_triangles();
    ASSERT_EQ(got.size(), want.size());
    const float step = 2.0f / float((1 << 11) - 1);  // the largest extent over 2^bits - 1 steps
    for (size_t t = 0; t < got.size(); ++t)
        for (size_t c = 0; c < 3; ++c)
            for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(got[t][c][k], want[t][c][k], step) << t << " " << c << " " << k;
    // Declared bounds off by more than a step are a located error.
    std::string json = draco_json(s, false);
    json.replace(json.find(R"("max": [2, 1, 0.5])"), 18, R"("max": [2, 0.9, 0.5])");
    const std::string err = error_text([&] { load_scene(write_file("draco_q11_max.gltf", json)); });
    EXPECT_NE(err.find("/accessors/0/max/1: the Draco stream decodes to 1.0"), std::string::npos) << err;
}

TEST(GltfDraco, MismatchesAndCorruptStreamsAreLocatedErrors) {
    const Stream s = encode(0);
    const std::string ext = "/meshes/0/primitives/0/extensions/KHR_draco_mesh_compression";
    auto err = [&](const std::string& name, const std::string& json) { return error_text([&] { load_scene(write_file(name, json)); }); };

    const std::string count = err("draco_count.gltf", draco_json(s, false, s.points + 1));
    EXPECT_NE(count.find(fmt::format("/accessors/0: count {} differs from the Draco stream's {} points", s.points + 1,
                                     s.points)),
              std::string::npos)
        << count;

    const std::string missing = err("draco_id.gltf", draco_json(s, false, 0, R"(, "TEXCOORD_1": 9)"));
    EXPECT_NE(missing.find(ext + "/attributes/TEXCOORD_1: the primitive has no TEXCOORD_1 attribute"), std::string::npos)
        << missing;

    std::string wrong_id = draco_json(s, false);
    wrong_id.replace(wrong_id.rfind(R"("_TEMPERATURE": 5)"), 17, R"("_TEMPERATURE": 7)");
    const std::string id = err("draco_wrong_id.gltf", wrong_id);
    EXPECT_NE(id.find("/accessors/5: the Draco stream in bufferView 0 has no attribute id 7"), std::string::npos) << id;

    std::string components = draco_json(s, false);
    components.replace(components.find(R"("count": )" + std::to_string(s.points) + R"(, "type": "VEC2")"),
                       std::string(R"("count": )" + std::to_string(s.points) + R"(, "type": "VEC2")").size(),
                       R"("count": )" + std::to_string(s.points) + R"(, "type": "VEC3")");
    const std::string comp = err("draco_components.gltf", components);
    EXPECT_NE(comp.find("/accessors/2: type has 3 components, the Draco attribute id 2 has 2"), std::string::npos) << comp;

    // Corrupt streams: truncated, and every byte after the header flipped. One located line each.
    Stream truncated = s;
    truncated.bytes.resize(s.bytes.size() / 2);
    const std::string cut = err("draco_cut.gltf", draco_json(truncated, false));
    EXPECT_NE(cut.find(ext + ": corrupt Draco stream in bufferView 0"), std::string::npos) << cut;
    EXPECT_EQ(cut.find('\n'), std::string::npos) << cut;
    Stream flipped = s;
    for (size_t i = 11; i < flipped.bytes.size(); ++i) flipped.bytes[i] ^= 0x5A;
    const std::string flip = err("draco_flip.gltf", draco_json(flipped, false));
    EXPECT_FALSE(flip.empty());
    EXPECT_EQ(flip.find('\n'), std::string::npos) << flip;
}

// A fuzzer finding (tests/data/fuzz-regressions/README.md): a Draco primitive whose attribute
// names an accessor past the array was read before anything checked it (ASan: use after free).
// Now one located error line.
TEST(GltfDraco, AttributeAccessorOutOfRangeIsALocatedError) {
    const std::string file =
        std::string(WHITTED_TEST_DATA_DIR) + "/fuzz-regressions/glb/asan-draco-attribute-accessor-out-of-range.glb";
    const std::string err = error_text([&] { load_scene(file); });
    EXPECT_NE(err.find(file + ": /meshes/0/primitives/0/attributes/POSITION: accessor out of range"), std::string::npos)
        << err;
}

}  // namespace
}  // namespace whitted::test

