// glTF animation posing through the importer (src/importers/gltf_animation.h): small GLB files
// built by hand, every expected number worked out from the glTF 2.0 specification (3.11
// Animations and Appendix C, 3.7.3 Skins, 3.7.2.2 Morph targets), then the bundled samples.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <fstream>
#include <filesystem>
#include <fmt/format.h>

#include "tests/support/test_importer_util.h"

namespace whitted::test {
namespace {

constexpr float kS45 = 0.70710678f;  ///< sin 45 deg = cos 45 deg: a 90 degree quaternion's parts

// ---------------------------------------------------------------------------------------------
// Hand-made GLB files

/// A "@key@" in a JSON template and the text that replaces it.
struct Sub {
    std::string key, value;
    Sub(const std::string& k, int v) : key("@" + k + "@"), value(std::to_string(v)) {}
    Sub(const std::string& k, std::string v) : key("@" + k + "@"), value(std::move(v)) {}
};

std::string fill(std::string json, std::initializer_list<Sub> subs) {
    for (const Sub& s : subs)
        for (size_t at = json.find(s.key); at != std::string::npos; at = json.find(s.key, at + s.value.size()))
            json.replace(at, s.key.size(), s.value);
    EXPECT_EQ(json.find('@'), std::string::npos) << "unfilled placeholder in " << json;
    return json;
}

/// A GLB with one BIN buffer: each accessor gets a bufferView of its own; glb() wraps the rest of
/// the JSON (nodes, meshes, animations, ...) around them.
class Glb {
public:
    /// A FLOAT accessor of `type` (SCALAR, VEC3, VEC4, MAT4); `bounds` writes min and max, which
    /// glTF requires of POSITION and of animation inputs.
    int floats(const std::vector<float>& values, const std::string& type, bool bounds = false) {
        const size_t n = components(type);
        std::string minmax;
        if (bounds) {
            std::vector<float> lo(values.begin(), values.begin() + long(n)), hi = lo;
            for (size_t i = 0; i < values.size(); ++i) {
                lo[i % n] = std::min(lo[i % n], values[i]);
                hi[i % n] = std::max(hi[i % n], values[i]);
            }
            minmax = ",\"min\":[" + join(lo) + "],\"max\":[" + join(hi) + "]";
        }
        const size_t offset = m_bin.size();
        for (const float v : values) m_bin.put<float>({v});
        return add(offset, values.size() / n, 5126, type, minmax);
    }

    /// An UNSIGNED_BYTE accessor (JOINTS_0).
    int ubytes(const std::vector<uint8_t>& values, const std::string& type) {
        const size_t offset = m_bin.size();
        for (const uint8_t v : values) m_bin.put<uint8_t>({v});
        return add(offset, values.size() / components(type), 5121, type, "");
    }

    std::vector<uint8_t> glb(const std::string& rest) const {
        const std::string json = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":" +
                                 std::to_string(m_bin.size()) + "}],\"bufferViews\":[" + m_views +
                                 "],\"accessors\":[" + m_accessors + "]," + rest + "}";
        return make_glb(json, m_bin.data);
    }

private:
    static size_t components(const std::string& type) {
        return type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : 16;
    }
    static std::string join(const std::vector<float>& v) {
        std::string s;
        for (const float x : v) {
            if (!s.empty()) s += ',';
            s += fmt::format("{}", x);
        }
        return s;
    }
    int add(size_t offset, size_t count, int component_type, const std::string& type, const std::string& minmax) {
        const size_t length = m_bin.size() - offset;
        m_bin.pad4();
        const int index = m_count++;
        m_views += fmt::format("{}{{\"buffer\":0,\"byteOffset\":{},\"byteLength\":{}}}", index ? "," : "", offset,
                               length);
        m_accessors += fmt::format("{}{{\"bufferView\":{},\"componentType\":{},\"count\":{},\"type\":\"{}\"{}}}",
                                   index ? "," : "", index, component_type, count, type, minmax);
        return index;
    }

    Bytes m_bin;
    std::string m_views, m_accessors;
    int m_count = 0;
};

/// The triangle most files here use: (0,0,0), (1,0,0), (0,1,0).
const std::vector<float> kTriangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};

/// One node "tri" (a triangle; `node_extra` adds JSON members) whose translation one sampler
/// ("move") drives with `times` and VEC3 `values`.
std::vector<uint8_t> animated_translation(const std::vector<float>& times, const std::vector<float>& values,
                                          const std::string& interpolation, const std::string& node_extra = "") {
    Glb b;
    const int pos = b.floats(kTriangle, "VEC3", true);
    const int in = b.floats(times, "SCALAR", true);
    const int out = b.floats(values, "VEC3");
    return b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0]}],
        "nodes":[{"name":"tri","mesh":0@extra@}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":@pos@}}]}],
        "animations":[{"name":"move","samplers":[{"input":@in@,"output":@out@,"interpolation":"@interp@"}],
                       "channels":[{"sampler":0,"target":{"node":0,"path":"translation"}}]}])",
                      {{"pos", pos}, {"in", in}, {"out", out}, {"interp", interpolation}, {"extra", node_extra}}));
}

ImportOptions at_time(double time, bool loop = false, const std::string& animation = "all") {
    ImportOptions o = no_textures();
    o.time = time;
    o.loop = loop;
    o.animation = animation;
    return o;
}

Scene import(const std::vector<uint8_t>& glb, const ImportOptions& options, const std::string& name = "anim.glb") {
    return import_gltf_memory(glb, name, options);
}

const Instance& instance_of(const Scene& s, const std::string& node_name) {
    for (const Instance& i : s.instances)
        if (i.node_name == node_name) return i;
    ADD_FAILURE() << "no instance of node " << node_name;
    static const Instance none;
    return none;
}

const Mesh& mesh_of(const Scene& s, const std::string& node_name) {
    const uint32_t m = instance_of(s, node_name).mesh;
    if (m < s.meshes.size()) return s.meshes[m];
    static const Mesh none;
    return none;
}

Vec3d origin_of(const Mat4d& m) { return m.apply_point(Vec3d(0.0)); }

/// Where node "tri" of `glb` is translated to at `time`.
Vec3d translation_at(const std::vector<uint8_t>& glb, double time, bool loop = false) {
    return origin_of(instance_of(import(glb, at_time(time, loop)), "tri").world_from_object);
}

/// `fn` must throw whitted::Error: one line that starts with `file` and holds every one of `parts`.
template <typename F>
void expect_error(F&& fn, const std::string& file, const std::vector<std::string>& parts) {
    const std::string e = error_text(fn);
    ASSERT_FALSE(e.empty()) << "no whitted::Error; expected one about " << parts.front();
    EXPECT_EQ(e.rfind(file, 0), 0u) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    for (const std::string& p : parts) EXPECT_NE(e.find(p), std::string::npos) << "'" << p << "' missing from: " << e;
}

// ---------------------------------------------------------------------------------------------
// 1. LINEAR translation: interpolation, clamping, --loop

// LINEAR from (0,0,0) at t=0 to (2,0,0) at t=1: x = 2t inside the keys (Appendix C). The node's
// own translation (9,9,9) is replaced by the animated one; its scale 2 stays (T * R * S).
TEST(GltfAnimation, LinearTranslationInterpolatesAndReplacesTheNodeTranslation) {
    const auto glb = animated_translation({0, 1}, {0, 0, 0, 2, 0, 0}, "LINEAR",
                                          R"(,"translation":[9,9,9],"scale":[2,2,2])");
    const Scene s = import(glb, at_time(0.25));
    const Mat4d& w = instance_of(s, "tri").world_from_object;
    EXPECT_VEC3_NEAR(origin_of(w), 0.5, 0.0, 0.0, 1e-6);
    EXPECT_NEAR(w(0, 0), 2.0, 1e-12);
    EXPECT_NEAR(w(1, 1), 2.0, 1e-12);
    EXPECT_NEAR(w(2, 2), 2.0, 1e-12);
    EXPECT_VEC3_NEAR(translation_at(glb, 0.0), 0.0, 0.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 0.75), 1.5, 0.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 1.0), 2.0, 0.0, 0.0, 1e-6);
    // After the last key the last value holds (section 3.11: clamped).
    EXPECT_VEC3_NEAR(translation_at(glb, 5.0), 2.0, 0.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 1.25), 2.0, 0.0, 0.0, 1e-6);
}

// KHR_animation_pointer: a pointer to a node's translation animates it like a core channel (in a
// GLB, whose JSON chunk is rewritten before tinygltf parses it); a pointer whitted does not apply
// (an extension of a node it does not know) is one warning naming it, and the rest of the
// animation still applies.
TEST(GltfAnimation, AnimationPointerToANodeAnimatesIt) {
    Glb b;
    const int pos = b.floats(kTriangle, "VEC3", true);
    const int in = b.floats({0, 1}, "SCALAR", true);
    const int out = b.floats({0, 0, 0, 2, 0, 0}, "VEC3");
    const int color = b.floats({1, 1, 1, 1, 0, 0, 0, 1}, "VEC4");
    const auto glb = b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0]}],"extensionsUsed":["KHR_animation_pointer"],
        "nodes":[{"name":"tri","mesh":0}],"materials":[{}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":@pos@},"material":0}]}],
        "animations":[{"samplers":[{"input":@in@,"output":@out@},{"input":@in@,"output":@color@}],
          "channels":[{"sampler":0,"target":{"path":"pointer",
                         "extensions":{"KHR_animation_pointer":{"pointer":"/nodes/0/translation"}}}},
                      {"sampler":1,"target":{"path":"pointer",
                         "extensions":{"KHR_animation_pointer":{"pointer":"/nodes/0/extensions/EXT_whatever/value"}}}}]}])",
                                {{"pos", pos}, {"in", in}, {"out", out}, {"color", color}}));
    EXPECT_VEC3_NEAR(translation_at(glb, 0.25), 0.5, 0.0, 0.0, 1e-6);
    const Scene s = import(glb, at_time(0.75));
    EXPECT_VEC3_NEAR(origin_of(instance_of(s, "tri").world_from_object), 1.5, 0.0, 0.0, 1e-6);
    size_t warned = 0;
    for (const std::string& w : s.warnings)
        warned += w.find("/nodes/0/extensions/EXT_whatever/value is not applied") != std::string::npos;
    EXPECT_EQ(warned, 1u);
}

// KHR_animation_pointer to KHR_texture_transform: the base colour texture's offset (VEC2, LINEAR
// from (0,0) to (1,0.5): halfway at 0.5 s) where the file has the extension object (its scale
// kept), and the normal texture's rotation (SCALAR, 0 to 1) where it has none (added).
TEST(GltfAnimation, AnimationPointerToTextureTransforms) {
    Glb b;
    const int pos = b.floats(kTriangle, "VEC3", true);
    const int uv = b.floats({0, 0, 1, 0, 0, 1}, "VEC2");
    const int in = b.floats({0, 1}, "SCALAR", true);
    const int offset = b.floats({0, 0, 1, 0.5f}, "VEC2");
    const int angle = b.floats({0, 1}, "SCALAR");
    const std::string png = "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQAAAABJRU5ErkJggg==";
    const auto glb = b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0]}],"extensionsUsed":["KHR_animation_pointer","KHR_texture_transform"],
        "nodes":[{"name":"tri","mesh":0}],"images":[{"uri":"@png@"}],"textures":[{"source":0}],
        "materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0,
                        "extensions":{"KHR_texture_transform":{"scale":[2,3]}}}},
                      "normalTexture":{"index":0}}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":@pos@,"TEXCOORD_0":@uv@},"material":0}]}],
        "animations":[{"samplers":[{"input":@in@,"output":@offset@},{"input":@in@,"output":@angle@}],
          "channels":[{"sampler":0,"target":{"path":"pointer",
                         "extensions":{"KHR_animation_pointer":{"pointer":"/materials/0/pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform/offset"}}}},
                      {"sampler":1,"target":{"path":"pointer",
                         "extensions":{"KHR_animation_pointer":{"pointer":"/materials/0/normalTexture/extensions/KHR_texture_transform/rotation"}}}}]}])",
                                {{"pos", pos}, {"uv", uv}, {"in", in}, {"offset", offset}, {"angle", angle}, {"png", png}}));
    const Scene half = import(glb, at_time(0.5));
    ASSERT_GE(half.materials.size(), 1u);
    const TextureTransform& base = half.materials[0].base_color_texture.transform;
    EXPECT_NEAR(base.offset.x, 0.5, 1e-6);
    EXPECT_NEAR(base.offset.y, 0.25, 1e-6);
    EXPECT_EQ(base.scale.x, 2.f);  // the file's, kept
    EXPECT_EQ(base.scale.y, 3.f);
    EXPECT_NEAR(half.materials[0].normal_texture.transform.rotation, 0.5, 1e-6);
    const Scene start = import(glb, at_time(0.0));
    EXPECT_TRUE(start.materials[0].normal_texture.transform.identity());
    EXPECT_EQ(start.materials[0].base_color_texture.transform.offset.x, 0.f);
    for (const std::string& w : half.warnings) EXPECT_EQ(w.find("is not applied"), std::string::npos) << w;

    // A sequence poses the same transforms in place, and says the materials changed.
    const std::filesystem::path path = std::filesystem::temp_directory_path() / "whitted_texture_transform_anim.glb";
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(glb.data()), std::streamsize(glb.size()));
    AnimatedScene anim = import_gltf_animated(path.string(), at_time(0.0));
    const SceneUpdate u = anim.animator->pose(anim.scene, 0.5);
    std::filesystem::remove(path);
    EXPECT_TRUE(u.materials);
    EXPECT_FALSE(u.reloaded);
    const TextureTransform& posed = anim.scene.materials[0].base_color_texture.transform;
    EXPECT_EQ(posed.offset, base.offset);
    EXPECT_EQ(posed.scale, base.scale);
    EXPECT_EQ(anim.scene.materials[0].normal_texture.transform.rotation, half.materials[0].normal_texture.transform.rotation);
}

// KHR_animation_pointer to core material factors: baseColorFactor (VEC4, component by component,
// not as a quaternion) and roughnessFactor, LINEAR over 0..1 s, halfway at 0.5 s; a value the
// spline takes past the factor's range is clamped to it (roughness keys 0.2 and 1.4: 1 at 1 s).
TEST(GltfAnimation, AnimationPointerToMaterialFactors) {
    Glb b;
    const int pos = b.floats(kTriangle, "VEC3", true);
    const int in = b.floats({0, 1}, "SCALAR", true);
    const int color = b.floats({1, 1, 1, 1, 0, 0.5f, 0, 1}, "VEC4");
    const int rough = b.floats({0.2f, 1.4f}, "SCALAR");
    const auto glb = b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0]}],"extensionsUsed":["KHR_animation_pointer"],
        "nodes":[{"name":"tri","mesh":0}],"materials":[{"pbrMetallicRoughness":{"roughnessFactor":0.7}}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":@pos@},"material":0}]}],
        "animations":[{"samplers":[{"input":@in@,"output":@color@},{"input":@in@,"output":@rough@}],
          "channels":[{"sampler":0,"target":{"path":"pointer",
                         "extensions":{"KHR_animation_pointer":{"pointer":"/materials/0/pbrMetallicRoughness/baseColorFactor"}}}},
                      {"sampler":1,"target":{"path":"pointer",
                         "extensions":{"KHR_animation_pointer":{"pointer":"/materials/0/pbrMetallicRoughness/roughnessFactor"}}}}]}])",
                                {{"pos", pos}, {"in", in}, {"color", color}, {"rough", rough}}));
    const Scene half = import(glb, at_time(0.5));
    ASSERT_GE(half.materials.size(), 1u);
    EXPECT_NEAR(half.materials[0].base_color.x, 0.5, 1e-6);
    EXPECT_NEAR(half.materials[0].base_color.y, 0.75, 1e-6);
    EXPECT_NEAR(half.materials[0].base_color.z, 0.5, 1e-6);
    EXPECT_NEAR(half.materials[0].base_color.w, 1.0, 1e-6);
    EXPECT_NEAR(half.materials[0].roughness, 0.8, 1e-6);
    const Scene end = import(glb, at_time(1.0));
    EXPECT_NEAR(end.materials[0].roughness, 1.0, 1e-6);  // 1.4 clamped
    for (const std::string& w : end.warnings) EXPECT_EQ(w.find("is not applied"), std::string::npos) << w;
}

// KHR_animation_pointer to the material extensions' factors: a clearcoat factor the file gives and
// a sheen colour on a material without the extension (the extension object is added), LINEAR over
// 0..1 s, read at 0.5 s; values past the range are clamped as the importer would.
TEST(GltfAnimation, AnimationPointerToMaterialExtensionFactors) {
    Glb b;
    const int pos = b.floats(kTriangle, "VEC3", true);
    const int in = b.floats({0, 1}, "SCALAR", true);
    const int coat = b.floats({0.2f, 1.6f}, "SCALAR");
    const int sheen = b.floats({0, 0, 0, 1, 0.5f, 0.25f}, "VEC3");
    const auto glb = b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0]}],
        "extensionsUsed":["KHR_animation_pointer","KHR_materials_clearcoat"],
        "nodes":[{"name":"tri","mesh":0}],
        "materials":[{"extensions":{"KHR_materials_clearcoat":{"clearcoatFactor":0.5,"clearcoatRoughnessFactor":0.3}}}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":@pos@},"material":0}]}],
        "animations":[{"samplers":[{"input":@in@,"output":@coat@},{"input":@in@,"output":@sheen@}],
          "channels":[{"sampler":0,"target":{"path":"pointer","extensions":{"KHR_animation_pointer":
                         {"pointer":"/materials/0/extensions/KHR_materials_clearcoat/clearcoatFactor"}}}},
                      {"sampler":1,"target":{"path":"pointer","extensions":{"KHR_animation_pointer":
                         {"pointer":"/materials/0/extensions/KHR_materials_sheen/sheenColorFactor"}}}}]}])",
                                {{"pos", pos}, {"in", in}, {"coat", coat}, {"sheen", sheen}}));
    const Scene still = import(glb, at_time(0.0));
    EXPECT_NEAR(still.materials[0].clearcoat, 0.2, 1e-6);
    const Scene half = import(glb, at_time(0.5));
    EXPECT_NEAR(half.materials[0].clearcoat, 0.9, 1e-6);
    EXPECT_NEAR(half.materials[0].clearcoat_roughness, 0.3, 1e-6);  // not animated: as the file gives it
    EXPECT_NEAR(half.materials[0].sheen_color.x, 0.5, 1e-6);
    EXPECT_NEAR(half.materials[0].sheen_color.y, 0.25, 1e-6);
    EXPECT_NEAR(half.materials[0].sheen_color.z, 0.125, 1e-6);
    EXPECT_TRUE(half.materials[0].layered());
    EXPECT_NEAR(import(glb, at_time(1.0)).materials[0].clearcoat, 1.0, 1e-6);  // 1.6 clamped
    for (const std::string& w : half.warnings) EXPECT_EQ(w.find("is not applied"), std::string::npos) << w;
}

// KHR_animation_pointer to a camera's yfov and a light's color and intensity (LINEAR from 0 s to
// 1 s, here at 0.5 s: halfway), and a yfov animated out of (0, pi) is an error naming the channel.
TEST(GltfAnimation, AnimationPointerToCameraAndLight) {
    auto file = [](float yfov_end) {
        Glb b;
        const int pos = b.floats(kTriangle, "VEC3", true);
        const int in = b.floats({0, 1}, "SCALAR", true);
        const int yfov = b.floats({0.5f, yfov_end}, "SCALAR");
        const int color = b.floats({1, 1, 1, 0, 0.5f, 1}, "VEC3");
        const int intensity = b.floats({0, 10}, "SCALAR");
        return b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0,1,2]}],"extensionsUsed":["KHR_animation_pointer","KHR_lights_punctual"],
            "extensions":{"KHR_lights_punctual":{"lights":[{"type":"point","color":[1,1,1],"intensity":3}]}},
            "cameras":[{"type":"perspective","perspective":{"yfov":0.5,"znear":0.1}}],
            "nodes":[{"name":"tri","mesh":0},{"camera":0,"translation":[0,0,5]},
                     {"extensions":{"KHR_lights_punctual":{"light":0}},"translation":[0,2,0]}],
            "meshes":[{"primitives":[{"attributes":{"POSITION":@pos@}}]}],
            "animations":[{"samplers":[{"input":@in@,"output":@yfov@},{"input":@in@,"output":@color@},
                                       {"input":@in@,"output":@intensity@}],
              "channels":[
                {"sampler":0,"target":{"path":"pointer","extensions":{"KHR_animation_pointer":{"pointer":"/cameras/0/perspective/yfov"}}}},
                {"sampler":1,"target":{"path":"pointer","extensions":{"KHR_animation_pointer":{"pointer":"/extensions/KHR_lights_punctual/lights/0/color"}}}},
                {"sampler":2,"target":{"path":"pointer","extensions":{"KHR_animation_pointer":{"pointer":"/extensions/KHR_lights_punctual/lights/0/intensity"}}}}]}])",
                                    {{"pos", pos}, {"in", in}, {"yfov", yfov}, {"color", color}, {"intensity", intensity}}));
    };
    const Scene s = import(file(1.0f), at_time(0.5));
    ASSERT_EQ(s.cameras.size(), 1u);
    EXPECT_NEAR(s.cameras[0].yfov, 0.75, 1e-6);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_VEC3_NEAR(s.lights[0].color, 0.5, 0.75, 1.0, 1e-6);
    EXPECT_NEAR(s.lights[0].intensity, 5.0, 1e-5);
    const Scene at0 = import(file(1.0f), at_time(0.0));
    EXPECT_NEAR(at0.cameras[0].yfov, 0.5, 1e-6);
    EXPECT_NEAR(at0.lights[0].intensity, 0.0, 1e-6);
    expect_error([&] { import(file(4.0f), at_time(1.0)); }, "anim.glb", {"/animations/0/channels/0", "camera yfov", "(0, pi)"});
}

// Keys at 1 s and 2 s: before the first key the first value holds.
TEST(GltfAnimation, BeforeTheFirstKeyTheFirstValueHolds) {
    const auto glb = animated_translation({1, 2}, {3, 0, 0, 5, 0, 0}, "LINEAR");
    EXPECT_VEC3_NEAR(translation_at(glb, 0.0), 3.0, 0.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 0.5), 3.0, 0.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 1.5), 4.0, 0.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 9.0), 5.0, 0.0, 0.0, 1e-6);
}

// --loop: the animation time is `time mod duration`, the duration being the last key time (the
// input accessor's max); the timeline starts at 0, not at the first key. So for keys 0..1 time
// 1.25 plays 0.25, and time 1 (one whole period) plays 0, the first value, not the last.
TEST(GltfAnimation, LoopPlaysTimeModuloTheDuration) {
    const auto glb = animated_translation({0, 1}, {0, 0, 0, 2, 0, 0}, "LINEAR");
    EXPECT_VEC3_NEAR(translation_at(glb, 1.25, true), 0.5, 0.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 3.75, true), 1.5, 0.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 0.5, true), 1.0, 0.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 1.0, true), 0.0, 0.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 2.0, true), 0.0, 0.0, 0.0, 1e-6);

    // Keys at 1 and 2 s: duration 2; time 2.5 plays 0.5 (before the first key), 3.5 plays 1.5.
    const auto late = animated_translation({1, 2}, {3, 0, 0, 5, 0, 0}, "LINEAR");
    EXPECT_VEC3_NEAR(translation_at(late, 2.5, true), 3.0, 0.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(late, 3.5, true), 4.0, 0.0, 0.0, 1e-6);
}

// ---------------------------------------------------------------------------------------------
// 2. A child under an animated parent

// Parent "arm": animated translation (2t, 0, 0) and a fixed 90 degree rotation about Z; child
// "hand" with translation (1,0,0) and the mesh. At t = 0.25 the child's world transform is
// T(0.5,0,0) Rz(90) T(1,0,0): origin -> (0.5,0,0) + Rz(90)(1,0,0) = (0.5, 1, 0); x axis -> +y.
TEST(GltfAnimation, ChildComposesItsAnimatedParent) {
    Glb b;
    const int pos = b.floats(kTriangle, "VEC3", true);
    const int in = b.floats({0, 1}, "SCALAR", true);
    const int out = b.floats({0, 0, 0, 2, 0, 0}, "VEC3");
    const auto glb = b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0]}],
        "nodes":[{"name":"arm","rotation":[0,0,@s@,@s@],"children":[1]},
                 {"name":"hand","translation":[1,0,0],"mesh":0}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":@pos@}}]}],
        "animations":[{"samplers":[{"input":@in@,"output":@out@}],
                       "channels":[{"sampler":0,"target":{"node":0,"path":"translation"}}]}])",
                                {{"pos", pos}, {"in", in}, {"out", out}, {"s", fmt::format("{}", kS45)}}));
    const Scene s = import(glb, at_time(0.25));
    ASSERT_EQ(s.instances.size(), 1u);
    const Mat4d& w = instance_of(s, "hand").world_from_object;
    EXPECT_VEC3_NEAR(origin_of(w), 0.5, 1.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(w.apply_vector({1, 0, 0}), 0.0, 1.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(w.apply_vector({0, 1, 0}), -1.0, 0.0, 0.0, 1e-6);
    // At t = 1 the parent is at (2,0,0): the child at (2, 1, 0).
    EXPECT_VEC3_NEAR(origin_of(instance_of(import(glb, at_time(1.0)), "hand").world_from_object), 2.0, 1.0, 0.0,
                     1e-6);
}

// ---------------------------------------------------------------------------------------------
// 3. STEP and CUBICSPLINE through the importer

// STEP keys 0, 1, 2 s with x = 0, 1, 5: a time holds the key at or before it.
TEST(GltfAnimation, StepHoldsTheKeyAtOrBeforeTheTime) {
    const auto glb = animated_translation({0, 1, 2}, {0, 0, 0, 1, 0, 0, 5, 0, 0}, "STEP");
    EXPECT_VEC3_NEAR(translation_at(glb, 0.99), 0.0, 0.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 1.0), 1.0, 0.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 1.5), 1.0, 0.0, 0.0, 1e-6);  // LINEAR would give 3
    EXPECT_VEC3_NEAR(translation_at(glb, 2.0), 5.0, 0.0, 0.0, 1e-6);
}

// CUBICSPLINE keys at 0 and 2 s (interval td = 2), output in-tangent, value, out-tangent per key:
//   key 0: a0 = (100,100,100) (unused), v0 = (0,1,0), b0 = (1,0,0)
//   key 1: a1 = (3,0,0), v1 = (4,1,0), b1 = (-100,-100,-100) (unused)
// Appendix C: p(u) = (2u^3-3u^2+1) v0 + (u^3-2u^2+u) td b0 + (-2u^3+3u^2) v1 + (u^3-u^2) td a1.
//   t = 1,   u = 1/2: x = 0.5*0 + 0.125*2*1 + 0.5*4 - 0.125*2*3 = 1.5   (without td: 1.75; LINEAR: 2)
//   t = 0.5, u = 1/4: x = 0.140625*2 + 0.15625*4 - 0.046875*2*3 = 0.625
//   y = h00*1 + h01*1 = 1 at every u; z = 0.
TEST(GltfAnimation, CubicSplineScalesTangentsByTheKeyInterval) {
    const auto glb = animated_translation(
        {0, 2}, {100, 100, 100, 0, 1, 0, 1, 0, 0, 3, 0, 0, 4, 1, 0, -100, -100, -100}, "CUBICSPLINE");
    EXPECT_VEC3_NEAR(translation_at(glb, 0.0), 0.0, 1.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 0.5), 0.625, 1.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 1.0), 1.5, 1.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 2.0), 4.0, 1.0, 0.0, 1e-6);
    EXPECT_VEC3_NEAR(translation_at(glb, 3.0), 4.0, 1.0, 0.0, 1e-6);
}

// ---------------------------------------------------------------------------------------------
// 4. Cameras and lights follow the animation

// Camera node: translation LINEAR (0,0,5) at 0 s -> (0,2,5) at 2 s; at 0.5 s (0, 0.5, 5).
// Spot light "lamp" at (0,0,-3) under "arm" (translation (0,1,0), rotation LINEAR from identity
// at 0 s to 90 degrees about Y at 1 s). At 0.5 s slerp gives 45 degrees: Ry(45)(0,0,-3) =
// (-3 sin45, 0, -3 cos45), so the light is at (-2.1213, 1, -2.1213), shining along
// Ry(45)(0,0,-1) = (-0.7071, 0, -0.7071).
TEST(GltfAnimation, CameraAndLightFollowTheirNodes) {
    Glb b;
    const int t2 = b.floats({0, 2}, "SCALAR", true);
    const int cam = b.floats({0, 0, 5, 0, 2, 5}, "VEC3");
    const int t1 = b.floats({0, 1}, "SCALAR", true);
    const int rot = b.floats({0, 0, 0, 1, 0, kS45, 0, kS45}, "VEC4");
    const auto glb = b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0,1]}],
        "nodes":[{"name":"cam","camera":0},
                 {"name":"arm","translation":[0,1,0],"children":[2]},
                 {"name":"lamp","translation":[0,0,-3],"extensions":{"KHR_lights_punctual":{"light":0}}}],
        "cameras":[{"type":"perspective","perspective":{"yfov":0.8,"znear":0.1}}],
        "extensionsUsed":["KHR_lights_punctual"],
        "extensions":{"KHR_lights_punctual":{"lights":[{"type":"spot","intensity":5,
                                                        "spot":{"innerConeAngle":0.1,"outerConeAngle":0.6}}]}},
        "animations":[{"samplers":[{"input":@t2@,"output":@cam@},{"input":@t1@,"output":@rot@}],
                       "channels":[{"sampler":0,"target":{"node":0,"path":"translation"}},
                                   {"sampler":1,"target":{"node":1,"path":"rotation"}}]}])",
                                {{"t2", t2}, {"cam", cam}, {"t1", t1}, {"rot", rot}}));
    const Scene s = import(glb, at_time(0.5));
    ASSERT_EQ(s.cameras.size(), 1u);
    EXPECT_FALSE(s.cameras[0].is_default);
    EXPECT_VEC3_NEAR(origin_of(s.cameras[0].world_from_camera), 0.0, 0.5, 5.0, 1e-6);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_VEC3_NEAR(s.lights[0].position, -3.0 * kS45, 1.0, -3.0 * kS45, 1e-5);
    EXPECT_VEC3_NEAR(s.lights[0].direction, -kS45, 0.0, -kS45, 1e-5);

    const Scene start = import(glb, at_time(0.0));
    EXPECT_VEC3_NEAR(origin_of(start.cameras[0].world_from_camera), 0.0, 0.0, 5.0, 1e-6);
    EXPECT_VEC3_NEAR(start.lights[0].position, 0.0, 1.0, -3.0, 1e-6);
    EXPECT_VEC3_NEAR(start.lights[0].direction, 0.0, 0.0, -1.0, 1e-6);
}

// ---------------------------------------------------------------------------------------------
// 5. Skins

/// What skinned_triangle() varies.
struct SkinVariant {
    std::vector<uint8_t> joints = {0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0};  ///< JOINTS_0, 4 a vertex
    bool inverse_bind = true;  ///< false: no inverseBindMatrices (section 3.7.3: identity each)
    bool morph = false;        ///< a POSITION target moving v1 by (0,1,0), mesh.weights (1)
};

/// A triangle skinned to two joints (section 3.7.3):
///   node 0 "skinned": mesh and skin, translation (100,0,0) which a skinned mesh ignores
///   node 1 "joint0" (skin joint 0): scale (1,2,1), in the scene
///   node 2 "joint1" (skin joint 1): translation (1,0,0), rotation animated LINEAR from identity at
///          0 s to 90 degrees about Z at 1 s; a root outside the scene's node list
/// Inverse bind matrices: identity, and T(-1,0,0) (joint 1's bind pose is at (1,0,0)).
/// Vertices, normals, joints (0,1,0,0) each, weights:
///   v0 (0,0,0), n (0,1,1)/sqrt2, weights (1, 0)
///   v1 (2,0,0), n (0,1,0),       weights (0.5, 0.5)
///   v2 (1,2,0), n (1,0,0),       weights (0.5, 1.5): sum 2, so (0.25, 0.75) once divided
std::vector<uint8_t> skinned_triangle(const SkinVariant& v = {}) {
    Glb b;
    const int pos = b.floats({0, 0, 0, 2, 0, 0, 1, 2, 0}, "VEC3", true);
    const int nrm = b.floats({0, kS45, kS45, 0, 1, 0, 1, 0, 0}, "VEC3");
    const int jnt = b.ubytes(v.joints, "VEC4");
    const int wgt = b.floats({1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 0.5f, 1.5f, 0, 0}, "VEC4");
    const int ibm = b.floats({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,  // column-major
                              1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1, 0, 0, 1},
                             "MAT4");
    const int in = b.floats({0, 1}, "SCALAR", true);
    const int out = b.floats({0, 0, 0, 1, 0, 0, kS45, kS45}, "VEC4");
    const int target = b.floats({0, 0, 0, 0, 1, 0, 0, 0, 0}, "VEC3", true);
    return b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0,1]}],
        "nodes":[{"name":"skinned","mesh":0,"skin":0,"translation":[100,0,0]},
                 {"name":"joint0","scale":[1,2,1]},
                 {"name":"joint1","translation":[1,0,0]}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":@pos@,"NORMAL":@nrm@,"JOINTS_0":@jnt@,
                                                "WEIGHTS_0":@wgt@}@targets@}]@weights@}],
        "skins":[{"name":"rig","joints":[1,2]@ibm@}],
        "animations":[{"name":"bend","samplers":[{"input":@in@,"output":@out@}],
                       "channels":[{"sampler":0,"target":{"node":2,"path":"rotation"}}]}])",
                      {{"pos", pos}, {"nrm", nrm}, {"jnt", jnt}, {"wgt", wgt},
                       {"ibm", v.inverse_bind ? ",\"inverseBindMatrices\":" + std::to_string(ibm) : ""},
                       {"targets", v.morph ? ",\"targets\":[{\"POSITION\":" + std::to_string(target) + "}]" : ""},
                       {"weights", v.morph ? ",\"weights\":[1]" : ""}, {"in", in}, {"out", out}}));
}

// Joint matrices global(joint) * inverseBind: J0 = S(1,2,1); at 1 s J1 = T(1,0,0) Rz(90) T(-1,0,0),
// p -> Rz(90)(p - (1,0,0)) + (1,0,0) with Rz(90)(x, y) = (-y, x).
//   v0: J0 (0,0,0) = (0,0,0)
//   v1: 0.5 (2,0,0) + 0.5 J1(2,0,0) = 0.5 (2,0,0) + 0.5 (1,1,0) = (1.5, 0.5, 0)
//   v2: 0.25 J0(1,2,0) + 0.75 J1(1,2,0) = 0.25 (1,4,0) + 0.75 (-1,0,0) = (-0.5, 1, 0)
// Normals by the inverse transpose of the blended 3x3 (xy block A, z untouched):
//   n0: S^-T = diag(1, 1/2, 1): (0, 1/2, 1) / |.| = (0, 1/sqrt5, 2/sqrt5)      [S itself: (0,2,1)/sqrt5]
//   n1: A = [[0.5,-0.5],[0.5,1]], A^-T (0,1) ~ (-0.5, 0.5) -> (-1, 1)/sqrt2    [A itself: (-1,2)/sqrt5]
//   n2: A = [[0.25,-0.75],[0.75,0.5]], A^-T (1,0) ~ (0.5, 0.75) -> (2, 3)/sqrt13 [A itself: (1,3)/sqrt10]
TEST(GltfAnimation, SkinPosesVerticesInWorldSpace) {
    const Scene s = import(skinned_triangle(), at_time(1.0));
    ASSERT_EQ(s.instances.size(), 1u);
    const Instance& inst = instance_of(s, "skinned");
    EXPECT_EQ(inst.world_from_object, Mat4d::identity());  // the node's (100,0,0) does not apply
    const Mesh& m = mesh_of(s, "skinned");
    ASSERT_EQ(m.positions.size(), 3u);
    EXPECT_VEC3_NEAR(m.positions[0], 0.f, 0.f, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(m.positions[1], 1.5f, 0.5f, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(m.positions[2], -0.5f, 1.f, 0.f, 1e-6f);  // weights not divided by 2: (-1, 1, 0)

    ASSERT_EQ(m.normals.size(), 3u);
    for (const Vec3f& n : m.normals) EXPECT_NEAR(length(n), 1.f, 1e-6f);
    EXPECT_VEC3_NEAR(m.normals[0], 0.f, 1.f / std::sqrt(5.f), 2.f / std::sqrt(5.f), 1e-6f);
    EXPECT_VEC3_NEAR(m.normals[1], -kS45, kS45, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(m.normals[2], 2.f / std::sqrt(13.f), 3.f / std::sqrt(13.f), 0.f, 1e-6f);

    ASSERT_EQ(s.skins.size(), 1u);
    EXPECT_EQ(s.skins[0].name, "rig");
    EXPECT_EQ(s.skins[0].joints, 2u);
    EXPECT_EQ(s.skins[0].meshes, 1u);
}

// At 0 s joint 1 is unrotated: J1 = T(1,0,0) T(-1,0,0) = I, so only joint 0's scale acts:
//   v1: 0.5 (2,0,0) + 0.5 (2,0,0) = (2,0,0); v2: 0.25 (1,4,0) + 0.75 (1,2,0) = (1, 2.5, 0).
// The joint outside the scene is posed by the animation: the two times differ.
TEST(GltfAnimation, SkinFollowsAJointOutsideTheScene) {
    const Scene s = import(skinned_triangle(), at_time(0.0));
    const Mesh& m = mesh_of(s, "skinned");
    ASSERT_EQ(m.positions.size(), 3u);
    EXPECT_VEC3_NEAR(m.positions[0], 0.f, 0.f, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(m.positions[1], 2.f, 0.f, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(m.positions[2], 1.f, 2.5f, 0.f, 1e-6f);
}

// Without inverseBindMatrices each is the identity (section 3.7.3): at 0 s J0 = S(1,2,1), J1 =
// T(1,0,0). v1: 0.5 (2,0,0) + 0.5 (3,0,0) = (2.5,0,0); v2: 0.25 (1,4,0) + 0.75 (2,2,0) = (1.75,2.5,0).
TEST(GltfAnimation, SkinWithoutInverseBindMatricesUsesIdentities) {
    const Mesh m = mesh_of(import(skinned_triangle({.inverse_bind = false}), at_time(0.0)), "skinned");
    ASSERT_EQ(m.positions.size(), 3u);
    EXPECT_VEC3_NEAR(m.positions[0], 0.f, 0.f, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(m.positions[1], 2.5f, 0.f, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(m.positions[2], 1.75f, 2.5f, 0.f, 1e-6f);
}

// Morph targets apply before the skin (section 3.7.2.2 / 3.7.3): at 1 s v1 is first morphed to
// (2,1,0), then skinned: 0.5 S(2,1,0) + 0.5 J1(2,1,0) = 0.5 (2,2,0) + 0.5 (0,1,0) = (1, 1.5, 0).
// (Skin first, then the displacement: (1.5,0.5,0) + (0,1,0) = (1.5,1.5,0).)
TEST(GltfAnimation, MorphTargetsApplyBeforeTheSkin) {
    const Scene s = import(skinned_triangle({.morph = true}), at_time(1.0));
    const Mesh& m = mesh_of(s, "skinned");
    ASSERT_EQ(m.positions.size(), 3u);
    EXPECT_VEC3_NEAR(m.positions[0], 0.f, 0.f, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(m.positions[1], 1.f, 1.5f, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(m.positions[2], -0.5f, 1.f, 0.f, 1e-6f);
    ASSERT_EQ(s.morphs.size(), 1u);
    EXPECT_EQ(s.morphs[0].default_weights, std::vector<float>{1.f});
}

// ---------------------------------------------------------------------------------------------
// 6. Morph targets

/// Meshes "morphed" (mesh.weights 0.5, 0.25) and "unweighted" (no weights), both the triangle with
/// normals (0,0,1) and two targets (section 3.7.2.2):
///   target 0: POSITION (0,0,1) each vertex, NORMAL (1,0,0) each vertex
///   target 1: POSITION (0,-1,0), (0,0,0), (0,0,0)
/// Nodes: "mesh-weights" (morphed), "node-weights" (morphed, node.weights 1, 0), "animated"
/// (morphed, node.weights 1, 0, and a weights channel LINEAR (0,0) at 0 s -> (1,2) at 1 s),
/// "zero" (unweighted).
std::vector<uint8_t> morph_file() {
    Glb b;
    const int pos = b.floats(kTriangle, "VEC3", true);
    const int nrm = b.floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
    const int t0p = b.floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", true);
    const int t0n = b.floats({1, 0, 0, 1, 0, 0, 1, 0, 0}, "VEC3");
    const int t1p = b.floats({0, -1, 0, 0, 0, 0, 0, 0, 0}, "VEC3", true);
    const int in = b.floats({0, 1}, "SCALAR", true);
    const int out = b.floats({0, 0, 1, 2}, "SCALAR");
    const std::string primitive = fill(R"({"attributes":{"POSITION":@pos@,"NORMAL":@nrm@},
        "targets":[{"POSITION":@t0p@,"NORMAL":@t0n@},{"POSITION":@t1p@}]})",
                                       {{"pos", pos}, {"nrm", nrm}, {"t0p", t0p}, {"t0n", t0n}, {"t1p", t1p}});
    return b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0,1,2,3]}],
        "nodes":[{"name":"mesh-weights","mesh":0},
                 {"name":"node-weights","mesh":0,"weights":[1,0]},
                 {"name":"animated","mesh":0,"weights":[1,0]},
                 {"name":"zero","mesh":1}],
        "meshes":[{"name":"morphed","weights":[0.5,0.25],"primitives":[@prim@]},
                  {"name":"unweighted","primitives":[@prim@]}],
        "animations":[{"name":"blend","samplers":[{"input":@in@,"output":@out@}],
                       "channels":[{"sampler":0,"target":{"node":2,"path":"weights"}}]}])",
                      {{"prim", primitive}, {"in", in}, {"out", out}}));
}

// base + sum w_i target_i; normals renormalised:
//   mesh.weights (0.5, 0.25): v0 (0,-0.25,0.5), v1 (1,0,0.5), v2 (0,1,0.5); n (0.5,0,1)/sqrt1.25
//   node.weights (1, 0) override mesh.weights: v0 (0,0,1), v1 (1,0,1), v2 (0,1,1); n (1,0,1)/sqrt2
//   the channel at 0.5 s, (0.5, 1), overrides node.weights: v0 (0,-1,0.5), v1 (1,0,0.5), v2 (0,1,0.5)
//   no weights anywhere: 0, the base triangle, n (0,0,1)
TEST(GltfAnimation, MorphWeightsFromMeshNodeAndAnimation) {
    const Scene s = import(morph_file(), at_time(0.5));
    ASSERT_EQ(s.instances.size(), 4u);
    const float n5 = 1.f / std::sqrt(1.25f);

    const Mesh& a = mesh_of(s, "mesh-weights");
    ASSERT_EQ(a.positions.size(), 3u);
    EXPECT_VEC3_NEAR(a.positions[0], 0.f, -0.25f, 0.5f, 1e-6f);
    EXPECT_VEC3_NEAR(a.positions[1], 1.f, 0.f, 0.5f, 1e-6f);
    EXPECT_VEC3_NEAR(a.positions[2], 0.f, 1.f, 0.5f, 1e-6f);
    for (const Vec3f& n : a.normals) EXPECT_VEC3_NEAR(n, 0.5f * n5, 0.f, n5, 1e-6f);

    const Mesh& b = mesh_of(s, "node-weights");
    ASSERT_EQ(b.positions.size(), 3u);
    EXPECT_VEC3_NEAR(b.positions[0], 0.f, 0.f, 1.f, 1e-6f);
    EXPECT_VEC3_NEAR(b.positions[1], 1.f, 0.f, 1.f, 1e-6f);
    EXPECT_VEC3_NEAR(b.positions[2], 0.f, 1.f, 1.f, 1e-6f);
    for (const Vec3f& n : b.normals) EXPECT_VEC3_NEAR(n, kS45, 0.f, kS45, 1e-6f);

    const Mesh& c = mesh_of(s, "animated");
    ASSERT_EQ(c.positions.size(), 3u);
    EXPECT_VEC3_NEAR(c.positions[0], 0.f, -1.f, 0.5f, 1e-6f);
    EXPECT_VEC3_NEAR(c.positions[1], 1.f, 0.f, 0.5f, 1e-6f);
    EXPECT_VEC3_NEAR(c.positions[2], 0.f, 1.f, 0.5f, 1e-6f);
    for (const Vec3f& n : c.normals) EXPECT_VEC3_NEAR(n, 0.5f * n5, 0.f, n5, 1e-6f);

    const Mesh& d = mesh_of(s, "zero");
    ASSERT_EQ(d.positions.size(), 3u);
    EXPECT_VEC3_NEAR(d.positions[0], 0.f, 0.f, 0.f, 0.f);
    EXPECT_VEC3_NEAR(d.positions[1], 1.f, 0.f, 0.f, 0.f);
    EXPECT_VEC3_NEAR(d.positions[2], 0.f, 1.f, 0.f, 0.f);
    for (const Vec3f& n : d.normals) EXPECT_VEC3_NEAR(n, 0.f, 0.f, 1.f, 1e-6f);

    // Instances are placed by their (untransformed) nodes; each morphed node has its own mesh.
    for (const Instance& i : s.instances) EXPECT_EQ(i.world_from_object, Mat4d::identity());
    EXPECT_NE(instance_of(s, "mesh-weights").mesh, instance_of(s, "node-weights").mesh);
    EXPECT_NE(instance_of(s, "node-weights").mesh, instance_of(s, "animated").mesh);

    ASSERT_EQ(s.morphs.size(), 2u);
    EXPECT_EQ(s.morphs[0].mesh, "morphed");
    EXPECT_EQ(s.morphs[0].targets, 2u);
    EXPECT_EQ(s.morphs[0].default_weights, (std::vector<float>{0.5f, 0.25f}));
    EXPECT_EQ(s.morphs[1].mesh, "unweighted");
    EXPECT_EQ(s.morphs[1].targets, 2u);
    EXPECT_TRUE(s.morphs[1].default_weights.empty());
}

// The channel's keys: (0,0) at 0 s and (1,2) at 1 s (after it: the last key holds).
TEST(GltfAnimation, MorphWeightsChannelAtItsKeys) {
    const Mesh start = mesh_of(import(morph_file(), at_time(0.0)), "animated");
    ASSERT_EQ(start.positions.size(), 3u);
    EXPECT_VEC3_NEAR(start.positions[0], 0.f, 0.f, 0.f, 1e-6f);  // weights (0,0), not node.weights (1,0)
    EXPECT_VEC3_NEAR(start.positions[2], 0.f, 1.f, 0.f, 1e-6f);
    const Mesh end = mesh_of(import(morph_file(), at_time(4.0)), "animated");
    ASSERT_EQ(end.positions.size(), 3u);
    EXPECT_VEC3_NEAR(end.positions[0], 0.f, -2.f, 1.f, 1e-6f);  // (1,2): (0,0,1) + 2 (0,-1,0)
    EXPECT_VEC3_NEAR(end.positions[1], 1.f, 0.f, 1.f, 1e-6f);
}

// ---------------------------------------------------------------------------------------------
// 7. Errors: one line, the file first, then the problem

/// Two animations, "move" and "spin", over node 0 (the triangle).
std::vector<uint8_t> two_animations() {
    Glb b;
    const int pos = b.floats(kTriangle, "VEC3", true);
    const int in = b.floats({0, 1}, "SCALAR", true);
    const int t = b.floats({0, 0, 0, 2, 0, 0}, "VEC3");
    const int r = b.floats({0, 0, 0, 1, 0, 0, kS45, kS45}, "VEC4");
    return b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0]}],
        "nodes":[{"name":"tri","mesh":0}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":@pos@}}]}],
        "animations":[{"name":"move","samplers":[{"input":@in@,"output":@t@}],
                       "channels":[{"sampler":0,"target":{"node":0,"path":"translation"}}]},
                      {"name":"spin","samplers":[{"input":@in@,"output":@r@}],
                       "channels":[{"sampler":0,"target":{"node":0,"path":"rotation"}}]}])",
                      {{"pos", pos}, {"in", in}, {"t", t}, {"r", r}}));
}

TEST(GltfAnimationErrors, UnknownAnimationNameListsTheAnimations) {
    const auto glb = two_animations();
    expect_error([&] { import(glb, at_time(0, false, "walk"), "errors.glb"); }, "errors.glb",
                 {"walk", "0 \"move\"", "1 \"spin\""});
    // A file without animations: "all" (the default) poses nothing; anything else is an error.
    Glb b;
    const int pos = b.floats(kTriangle, "VEC3", true);
    const auto still = b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"name":"tri","mesh":0}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":@pos@}}]}])",
                                  {{"pos", pos}}));
    EXPECT_TRUE(import(still, at_time(0)).animations.empty());
    expect_error([&] { import(still, at_time(0, false, "0"), "still.glb"); }, "still.glb", {"'0'", "no animation"});
}

TEST(GltfAnimationErrors, AnimationIndexOutOfRange) {
    const auto glb = two_animations();
    expect_error([&] { import(glb, at_time(0, false, "2"), "errors.glb"); }, "errors.glb",
                 {"'2'", "0 \"move\"", "1 \"spin\""});
    expect_error([&] { import(glb, at_time(0, false, "0,7"), "errors.glb"); }, "errors.glb", {"'7'"});
    expect_error([&] { import(glb, at_time(0, false, "-1"), "errors.glb"); }, "errors.glb", {"'-1'"});
    // Valid choices import.
    EXPECT_NO_THROW(import(glb, at_time(0, false, "1")));
    EXPECT_NO_THROW(import(glb, at_time(0, false, "1,0")));
    EXPECT_NO_THROW(import(glb, at_time(0, false, "spin")));
}

TEST(GltfAnimationErrors, KeyTimesNotIncreasing) {
    const auto glb = animated_translation({0, 1, 1}, {0, 0, 0, 1, 0, 0, 2, 0, 0}, "LINEAR");
    expect_error([&] { import(glb, at_time(0), "errors.glb"); }, "errors.glb",
                 {"/animations/0/samplers/0", "strictly increasing"});
}

TEST(GltfAnimationErrors, CubicSplineNeedsThreeValuesAKey) {
    const auto glb = animated_translation({0, 1}, {0, 0, 0, 1, 0, 0}, "CUBICSPLINE");
    expect_error([&] { import(glb, at_time(0), "errors.glb"); }, "errors.glb",
                 {"/animations/0/samplers/0", "CUBICSPLINE", "3 values a key"});
}

/// The morph triangle (2 targets) on node 0; `mesh_extra` and `node_extra` add JSON members.
std::vector<uint8_t> morph_with(const std::string& mesh_extra, const std::string& node_extra,
                                const std::vector<float>& animated_weights = {}) {
    Glb b;
    const int pos = b.floats(kTriangle, "VEC3", true);
    const int t0 = b.floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", true);
    const int t1 = b.floats({0, -1, 0, 0, 0, 0, 0, 0, 0}, "VEC3", true);
    std::string animations;
    if (!animated_weights.empty()) {
        const int in = b.floats({0, 1}, "SCALAR", true);
        const int out = b.floats(animated_weights, "SCALAR");
        animations = fill(R"(,"animations":[{"samplers":[{"input":@in@,"output":@out@}],
                           "channels":[{"sampler":0,"target":{"node":0,"path":"weights"}}]}])",
                          {{"in", in}, {"out", out}});
    }
    return b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0]}],
        "nodes":[{"name":"tri","mesh":0@node@}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":@pos@},
                                  "targets":[{"POSITION":@t0@},{"POSITION":@t1@}]}]@mesh@}]@anim@)",
                      {{"pos", pos}, {"t0", t0}, {"t1", t1}, {"node", node_extra}, {"mesh", mesh_extra},
                       {"anim", animations}}));
}

TEST(GltfAnimationErrors, WeightsCountDiffersFromTheTargets) {
    expect_error([&] { import(morph_with("", R"(,"weights":[1])"), at_time(0), "errors.glb"); }, "errors.glb",
                 {"/nodes/0/weights", "1 weights for 2 morph targets"});
    expect_error([&] { import(morph_with(R"(,"weights":[1,0,0])", ""), at_time(0), "errors.glb"); }, "errors.glb",
                 {"/meshes/0/weights", "3 weights for 2 morph targets"});
    // An animated weights output of 3 values for 2 keys x 2 targets.
    expect_error([&] { import(morph_with("", "", {0, 0, 1}), at_time(0), "errors.glb"); }, "errors.glb",
                 {"/animations/0/samplers/0", "3 values"});
    // The right counts import.
    EXPECT_NO_THROW(import(morph_with(R"(,"weights":[1,0])", R"(,"weights":[0,1])", {0, 0, 1, 1}), at_time(0)));
}

TEST(GltfAnimationErrors, JointOutsideTheSkin) {
    // Vertex 1 names joint 2 (weight 0.5) of a skin with joints 0 and 1.
    const auto glb = skinned_triangle({.joints = {0, 1, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0}});
    expect_error([&] { import(glb, at_time(0), "errors.glb"); }, "errors.glb",
                 {"JOINTS_0", "vertex 1", "outside skin 0"});
}

TEST(GltfAnimationErrors, ChannelTargetsANodeWithAMatrix) {
    const auto glb = animated_translation({0, 1}, {0, 0, 0, 2, 0, 0}, "LINEAR",
                                          R"(,"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1])");
    expect_error([&] { import(glb, at_time(0), "errors.glb"); }, "errors.glb",
                 {"/animations/0/channels/0", "matrix"});
}

TEST(GltfAnimationErrors, TimeMustBeFiniteAndNotNegative) {
    for (const double t : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(), -1.0}) {
        const std::string e = error_text([&] { check_animation_time(t, "--time"); });
        EXPECT_EQ(e.rfind("--time", 0), 0u) << e;
        EXPECT_NE(e.find("finite number of seconds"), std::string::npos) << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
        // The importer refuses it too.
        EXPECT_NE(error_text([&] { import(two_animations(), at_time(t)); }).find("--time"), std::string::npos);
    }
    EXPECT_NE(error_text([] { check_animation_time(-1.0, "--time"); }).find("-1"), std::string::npos);
    EXPECT_NE(error_text([] { check_animation_time(std::numeric_limits<double>::quiet_NaN(), "--time"); }).find("nan"),
              std::string::npos);
    EXPECT_NO_THROW(check_animation_time(0.0, "--time"));
    EXPECT_NO_THROW(check_animation_time(1e6, "--time"));
}

// ---------------------------------------------------------------------------------------------
// 8. Scene records

/// Node "a" moved by animation 0 "move" (LINEAR, keys 0..1 s); node "b" by the unnamed animation 1:
/// scale STEP (1,1,1) at 0.5 s, (3,3,3) at 2.5 s, and translation CUBICSPLINE keys 0 and 2 s
/// ending at (4,1,0). Its duration is the larger input max, 2.5 s.
std::vector<uint8_t> records_file() {
    Glb b;
    const int pos = b.floats(kTriangle, "VEC3", true);
    const int in0 = b.floats({0, 1}, "SCALAR", true);
    const int move = b.floats({0, 0, 0, 2, 0, 0}, "VEC3");
    const int in1 = b.floats({0.5f, 2.5f}, "SCALAR", true);
    const int scale = b.floats({1, 1, 1, 3, 3, 3}, "VEC3");
    const int in2 = b.floats({0, 2}, "SCALAR", true);
    const int cubic = b.floats({100, 100, 100, 0, 1, 0, 1, 0, 0, 3, 0, 0, 4, 1, 0, -100, -100, -100}, "VEC3");
    return b.glb(fill(R"("scene":0,"scenes":[{"nodes":[0,1]}],
        "nodes":[{"name":"a","mesh":0},{"name":"b","mesh":0}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":@pos@}}]}],
        "animations":[{"name":"move","samplers":[{"input":@in0@,"output":@move@,"interpolation":"LINEAR"}],
                       "channels":[{"sampler":0,"target":{"node":0,"path":"translation"}}]},
                      {"samplers":[{"input":@in1@,"output":@scale@,"interpolation":"STEP"},
                                   {"input":@in2@,"output":@cubic@,"interpolation":"CUBICSPLINE"}],
                       "channels":[{"sampler":0,"target":{"node":1,"path":"scale"}},
                                   {"sampler":1,"target":{"node":1,"path":"translation"}}]}])",
                      {{"pos", pos}, {"in0", in0}, {"move", move}, {"in1", in1}, {"scale", scale}, {"in2", in2},
                       {"cubic", cubic}}));
}

std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    size_t start = 0;
    for (size_t comma; (comma = s.find(',', start)) != std::string::npos; start = comma + 1)
        out.push_back(s.substr(start, comma - start));
    out.push_back(s.substr(start));
    std::sort(out.begin(), out.end());
    return out;
}

TEST(GltfAnimation, SceneRecordsTheAnimationsAndWhichArePosed) {
    const Scene s = import(records_file(), at_time(2.5, false, "1"));
    EXPECT_EQ(s.time, 2.5);
    ASSERT_EQ(s.animations.size(), 2u);
    EXPECT_EQ(s.animations[0].name, "move");
    EXPECT_FLOAT_EQ(s.animations[0].duration, 1.f);
    EXPECT_EQ(s.animations[0].channels, 1u);
    EXPECT_EQ(s.animations[0].interpolations, "LINEAR");
    EXPECT_FALSE(s.animations[0].posed);
    EXPECT_EQ(s.animations[1].name, "animation 1");
    EXPECT_FLOAT_EQ(s.animations[1].duration, 2.5f);
    EXPECT_EQ(s.animations[1].channels, 2u);
    EXPECT_EQ(split(s.animations[1].interpolations), (std::vector<std::string>{"CUBICSPLINE", "STEP"}));
    EXPECT_TRUE(s.animations[1].posed);
    EXPECT_TRUE(s.skins.empty());
    EXPECT_TRUE(s.morphs.empty());

    // Only animation 1 applies: "a" stays at the origin (move would put it at (2,0,0)); "b" is
    // T(4,1,0) S(3) (both samplers past their last key).
    EXPECT_EQ(instance_of(s, "a").world_from_object, Mat4d::identity());
    const Mat4d& b = instance_of(s, "b").world_from_object;
    EXPECT_VEC3_NEAR(origin_of(b), 4.0, 1.0, 0.0, 1e-6);
    EXPECT_NEAR(b(0, 0), 3.0, 1e-6);
    EXPECT_NEAR(b(1, 1), 3.0, 1e-6);

    // By name, by indices, all.
    const Scene by_name = import(records_file(), at_time(2.5, false, "move"));
    EXPECT_TRUE(by_name.animations[0].posed);
    EXPECT_FALSE(by_name.animations[1].posed);
    EXPECT_VEC3_NEAR(origin_of(instance_of(by_name, "a").world_from_object), 2.0, 0.0, 0.0, 1e-6);
    EXPECT_EQ(instance_of(by_name, "b").world_from_object, Mat4d::identity());
    for (const char* choice : {"all", "0,1"}) {
        const Scene all = import(records_file(), at_time(0.0, false, choice));
        EXPECT_EQ(all.time, 0.0);
        EXPECT_TRUE(all.animations[0].posed) << choice;
        EXPECT_TRUE(all.animations[1].posed) << choice;
    }
}

// ---------------------------------------------------------------------------------------------
// 9. Bundled samples (assets/gltf, Khronos glTF Sample Assets)

std::vector<Vec3f> world_positions(const Scene& s) {
    std::vector<Vec3f> out;
    for (const Instance& i : s.instances)
        for (const Vec3f& p : s.meshes[i.mesh].positions)
            out.push_back(Vec3f(i.world_from_object.apply_point(Vec3d(p))));
    return out;
}

float largest_move(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    EXPECT_EQ(a.size(), b.size());
    float d = 0.f;
    for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) d = std::max(d, length(a[i] - b[i]));
    return d;
}

// SimpleSkin (read from its .bin files): vertices 8 and 9 at (-0.5,2,0) and (0.5,2,0), all weight
// on joint 1 (node 2 at (0,1,0) under node 1; inverse bind T(0,-1,0)). Its rotation keys (0.5 s
// apart): identity at 0 s, (0,0,0.383,0.924) ~ 45 degrees about Z at 2 s. So at 0 s the mesh is
// its base geometry; at 2 s p -> Rz(45)(p - (0,1,0)) + (0,1,0):
//   v8: (-0.5, 1) -> (0.7071 (-0.5 - 1), 0.7071 (-0.5 + 1)) + (0,1) = (-1.0607, 1.3536)
//   v9: ( 0.5, 1) -> (0.7071 ( 0.5 - 1), 0.7071 ( 0.5 + 1)) + (0,1) = (-0.3536, 2.0607)
// The keys are rounded to 3 digits (45.03 degrees): tolerance 2e-3.
TEST(GltfAnimationSamples, SimpleSkinBendsBetweenTimes) {
    const Scene s0 = import_gltf(asset("SimpleSkin/glTF/SimpleSkin.gltf"), at_time(0.0));
    const Scene s2 = import_gltf(asset("SimpleSkin/glTF/SimpleSkin.gltf"), at_time(2.0));
    ASSERT_EQ(s0.instances.size(), 1u);
    EXPECT_EQ(s0.instances[0].world_from_object, Mat4d::identity());
    const std::vector<Vec3f> p0 = world_positions(s0), p2 = world_positions(s2);
    ASSERT_EQ(p0.size(), 10u);
    EXPECT_VEC3_NEAR(p0[8], -0.5f, 2.f, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(p0[9], 0.5f, 2.f, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(p0[0], -0.5f, 0.f, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(p2[8], -1.0607f, 1.3536f, 0.f, 2e-3f);
    EXPECT_VEC3_NEAR(p2[9], -0.3536f, 2.0607f, 0.f, 2e-3f);
    EXPECT_VEC3_NEAR(p2[0], -0.5f, 0.f, 0.f, 1e-6f);  // weight 1 on joint 0, which does not move
    EXPECT_GT(largest_move(p0, p2), 0.5f);
}

// CesiumMan walks (one animation, keys 0.0417..2 s, 19 joints). Its bind-pose POSITION bounds are
// x -0.13..0.18, y -0.57..0.57, z 0..1.51, turned to Y-up by its root matrices: a man ~1.5 tall.
TEST(GltfAnimationSamples, CesiumManMovesAndStaysManSized) {
    const Scene s0 = import_gltf(asset("CesiumMan/glTF-Binary/CesiumMan.glb"), at_time(0.0));
    const Scene s1 = import_gltf(asset("CesiumMan/glTF-Binary/CesiumMan.glb"), at_time(1.0));
    ASSERT_EQ(s0.animations.size(), 1u);
    EXPECT_NEAR(s0.animations[0].duration, 2.0, 1e-6);
    ASSERT_EQ(s0.skins.size(), 1u);
    EXPECT_EQ(s0.skins[0].joints, 19u);
    EXPECT_EQ(s0.skins[0].meshes, 1u);
    const std::vector<Vec3f> p0 = world_positions(s0), p1 = world_positions(s1);
    EXPECT_GT(largest_move(p0, p1), 0.05f);
    for (const auto* p : {&p0, &p1}) {
        Bounds3d b;
        for (const Vec3f& v : *p) {
            ASSERT_TRUE(is_finite(v));
            b.extend(Vec3d(v));
        }
        const Vec3d size = b.diagonal();
        EXPECT_GT(size.y, 1.2);
        EXPECT_LT(size.y, 1.8);
        EXPECT_LT(size.x, 1.5);
        EXPECT_LT(size.z, 1.5);
    }
}

// RiggedSimple: a cylinder bent by its second bone; times 0 and 1 s differ.
TEST(GltfAnimationSamples, RiggedSimpleBends) {
    const Scene s0 = import_gltf(asset("RiggedSimple/glTF-Binary/RiggedSimple.glb"), at_time(0.0));
    const Scene s1 = import_gltf(asset("RiggedSimple/glTF-Binary/RiggedSimple.glb"), at_time(1.0));
    const std::vector<Vec3f> p0 = world_positions(s0), p1 = world_positions(s1);
    for (const Vec3f& v : p1) ASSERT_TRUE(is_finite(v));
    EXPECT_GT(largest_move(p0, p1), 0.05f);
}

// MorphPrimitivesTest: mesh.weights (0.5), one POSITION target per primitive. The base
// POSITION accessors (2 and 7) are flat, y in [0, 0]; the targets (4 and 9) only move y, within
// [0, 0.2]. Weighted 0.5 the surface rises to y = 0.1 at most; x and z keep the base bounds
// (primitive 0: -0.5..0.5 both; primitive 1: x 0..0.5, z -0.5..0).
TEST(GltfAnimationSamples, MorphPrimitivesTestIsNotItsBaseGeometry) {
    const Scene s = import_gltf(asset("MorphPrimitivesTest/glTF-Binary/MorphPrimitivesTest.glb"), at_time(0.0));
    ASSERT_EQ(s.instances.size(), 2u);
    ASSERT_EQ(s.morphs.size(), 1u);
    EXPECT_EQ(s.morphs[0].default_weights, std::vector<float>{0.5f});
    const Bounds3d b0 = s.meshes[s.instances[0].mesh].bounds(), b1 = s.meshes[s.instances[1].mesh].bounds();
    EXPECT_NEAR(b0.hi.y, 0.1, 1e-6);
    EXPECT_NEAR(b0.lo.y, 0.0, 1e-6);
    EXPECT_NEAR(b1.hi.y, 0.1, 1e-6);
    EXPECT_NEAR(b0.lo.x, -0.5, 1e-6);
    EXPECT_NEAR(b0.hi.x, 0.5, 1e-6);
    EXPECT_NEAR(b0.lo.z, -0.5, 1e-6);
    EXPECT_NEAR(b0.hi.z, 0.5, 1e-6);
    EXPECT_NEAR(b1.lo.x, 0.0, 1e-6);
    EXPECT_NEAR(b1.hi.x, 0.5, 1e-6);
    EXPECT_NEAR(b1.lo.z, -0.5, 1e-6);
    EXPECT_NEAR(b1.hi.z, 0.0, 1e-6);
}

// SimpleMorph (read from its .bin files): base triangle (0,0,0), (1,0,0), (0.5,0.5,0); targets
// move vertex 2 by (-1,1,0) and (1,1,0); the weights channel has keys (0,0), (0,1), (1,1), (1,0),
// (0,0) at 0..4 s, and overrides mesh.weights (0.5, 0.5). At 1.5 s the weights are (0.5, 1):
// v2 = (0.5,0.5,0) + 0.5 (-1,1,0) + (1,1,0) = (1, 2, 0). At 0 s (0,0): the base.
TEST(GltfAnimationSamples, SimpleMorphFollowsItsWeightsChannel) {
    const std::string file = asset("SimpleMorph/glTF/SimpleMorph.gltf");
    const std::vector<Vec3f> p = world_positions(import_gltf(file, at_time(1.5)));
    ASSERT_EQ(p.size(), 3u);
    EXPECT_VEC3_NEAR(p[0], 0.f, 0.f, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(p[1], 1.f, 0.f, 0.f, 1e-6f);
    EXPECT_VEC3_NEAR(p[2], 1.f, 2.f, 0.f, 1e-6f);
    const std::vector<Vec3f> base = world_positions(import_gltf(file, at_time(0.0)));
    ASSERT_EQ(base.size(), 3u);
    EXPECT_VEC3_NEAR(base[2], 0.5f, 0.5f, 0.f, 1e-6f);
}

// AnimatedTriangle: rotation keys 0, 90, 180, 270, 360 degrees about Z at 0, 0.25, .. 1 s (stored
// as 0.707 pairs, normalised before use). At 0.25 s: 90 degrees; at 0.375 s slerp halfway from 90
// to 180: 135 degrees, so x -> (cos 135, sin 135) = (-0.7071, 0.7071).
TEST(GltfAnimationSamples, AnimatedTriangleRotates) {
    const std::string file = asset("AnimatedTriangle/glTF/AnimatedTriangle.gltf");
    const Mat4d w90 = import_gltf(file, at_time(0.25)).instances.at(0).world_from_object;
    EXPECT_VEC3_NEAR(w90.apply_vector({1, 0, 0}), 0.0, 1.0, 0.0, 1e-6);
    const Mat4d w135 = import_gltf(file, at_time(0.375)).instances.at(0).world_from_object;
    EXPECT_VEC3_NEAR(w135.apply_vector({1, 0, 0}), -kS45, kS45, 0.0, 1e-6);
}

}  // namespace
}  // namespace whitted::test
