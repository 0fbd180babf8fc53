// The Khronos material extensions read into whitted::Material (docs/gltf-support.md, extension
// table): clearcoat, sheen, iridescence, anisotropy, dispersion, diffuse transmission and
// specular-glossiness. Hand-made files of one textured quad: every factor and textureInfo lands
// in its field (channel, sRGB-ness, KHR_texture_transform, texCoord), absent extensions keep the
// defaults, out-of-range factors are clamped with one warning, bad values are one error naming the
// file and the JSON pointer, and anisotropy or a coat normal map gets tangents. Then the bundled
// ClearCoatTest and AnisotropyRotationTest samples, and the `whitted info` line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <vector>

#include "importers/scene_loader.h"
#include "importers/scene_report.h"
#include "shading/texture_sampling.h"
#include "tests/support/test_importer_util.h"

namespace whitted::test {
namespace {

/// A unit quad in the XY plane with TEXCOORD_0 (u = x, v = 1 - y: tangent +X) and TEXCOORD_1
/// (u = y, v = x: tangent +Y), using material 0 of `materials` (a JSON array). Four textures of one
/// 1x1 RGBA PNG holding `texel` are available (indices 0-3). `extensions_used` and
/// `extensions_required` are JSON arrays.
std::string quad_file(const std::string& name, const std::string& materials,
                      const std::string& extensions_used = "[]", const std::string& extensions_required = "[]",
                      const std::vector<uint8_t>& texel = {128, 128, 255, 255}) {
    Bytes b;
    b.put<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});  // 48 bytes of positions
    b.put<uint16_t>({0, 1, 2, 0, 2, 3});                 // 12 bytes of indices
    b.put<float>({0, 1, 1, 1, 1, 0, 0, 0});              // TEXCOORD_0 at 60
    b.put<float>({0, 0, 0, 1, 1, 1, 1, 0});              // TEXCOORD_1 at 92
    const std::vector<uint8_t> png = make_png(1, 1, 8, 6, texel);
    const std::string json = R"({
  "asset": {"version": "2.0"},
  "extensionsUsed": )" + extensions_used + R"(, "extensionsRequired": )" + extensions_required + R"(,
  "buffers": [{"uri": ")" + data_uri(b.data) + R"(", "byteLength": )" + std::to_string(b.size()) + R"(}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12},
                  {"buffer": 0, "byteOffset": 60, "byteLength": 32}, {"buffer": 0, "byteOffset": 92, "byteLength": 32}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]},
                {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
                {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
                {"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC2"}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 2, "TEXCOORD_1": 3}, "indices": 1,
                              "material": 0}]}],
  "materials": )" + materials + R"(,
  "textures": [{"source": 0}, {"source": 0}, {"source": 0}, {"source": 0}],
  "images": [{"uri": ")" + data_uri(png, "image/png") + R"("}],
  "nodes": [{"mesh": 0}],
  "scenes": [{"nodes": [0]}],
  "scene": 0
})";
    return write_file(name, json);
}

/// Options for these tests: textures not decoded (the tests look at references), no environment.
ImportOptions quick() {
    ImportOptions o = no_textures();
    o.default_environment = false;
    return o;
}

/// The scene of quad_file(name, materials).
Scene load(const std::string& name, const std::string& materials) {
    return load_scene(quad_file(name, materials), quick());
}

/// The sRGB flag of the Scene texture `ref` points at (the reference must be valid).
bool srgb(const Scene& s, const TextureRef& ref) {
    EXPECT_TRUE(ref.valid());
    return ref.valid() && s.textures.at(size_t(ref.texture)).srgb;
}

size_t warnings_containing(const Scene& s, const std::string& text) {
    return size_t(std::count_if(s.warnings.begin(), s.warnings.end(),
                                [&](const std::string& w) { return w.find(text) != std::string::npos; }));
}

/// The message of the std::exception `fn` throws ("" when none); it must name `file` and `pointer`.
template <typename F>
void expect_located_error(F&& fn, const std::string& file, const std::string& pointer) {
    std::string message;
    try {
        fn();
    } catch (const std::exception& e) {
        message = e.what();
    }
    ASSERT_FALSE(message.empty()) << "no error; expected one at " << pointer;
    EXPECT_NE(message.find(file), std::string::npos) << message;
    EXPECT_NE(message.find(pointer + ":"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

// ---- each extension's fields ------------------------------------------------------------------

TEST(GltfMaterialExtensions, ClearcoatFactorsTexturesTransformAndNormalScale) {
    const Scene s = load("clearcoat.gltf", R"([{"extensions": {"KHR_materials_clearcoat": {
        "clearcoatFactor": 0.8,
        "clearcoatTexture": {"index": 0, "extensions": {"KHR_texture_transform":
                             {"offset": [0.25, 0.5], "scale": [2, 3], "rotation": 0.5, "texCoord": 1}}},
        "clearcoatRoughnessFactor": 0.3,
        "clearcoatRoughnessTexture": {"index": 1, "texCoord": 1},
        "clearcoatNormalTexture": {"index": 2, "scale": 0.7}}}}])");
    const Material& m = s.materials.at(0);
    EXPECT_FLOAT_EQ(m.clearcoat, 0.8f);
    EXPECT_FLOAT_EQ(m.clearcoat_roughness, 0.3f);
    EXPECT_FALSE(srgb(s, m.clearcoat_texture));
    EXPECT_FALSE(srgb(s, m.clearcoat_roughness_texture));
    EXPECT_FALSE(srgb(s, m.clearcoat_normal_texture));
    // KHR_texture_transform on an extension's textureInfo, its texCoord overriding the slot's (0).
    EXPECT_EQ(m.clearcoat_texture.transform.offset, Vec2f(0.25f, 0.5f));
    EXPECT_EQ(m.clearcoat_texture.transform.scale, Vec2f(2.f, 3.f));
    EXPECT_FLOAT_EQ(m.clearcoat_texture.transform.rotation, 0.5f);
    EXPECT_EQ(m.clearcoat_texture.uv_set, 1u);
    EXPECT_EQ(m.clearcoat_roughness_texture.uv_set, 1u);
    EXPECT_TRUE(m.clearcoat_roughness_texture.transform.identity());
    // normalTextureInfo.scale kept like the core normalTexture's; the other slots keep scale 1.
    EXPECT_FLOAT_EQ(m.clearcoat_normal_texture.scale, 0.7f);
    EXPECT_FLOAT_EQ(m.clearcoat_texture.scale, 1.f);
    EXPECT_EQ(m.clearcoat_normal_texture.uv_set, 0u);
    EXPECT_TRUE(m.layered());
    // One linear Scene texture per glTF texture used.
    EXPECT_EQ(s.textures.size(), 3u);
}

TEST(GltfMaterialExtensions, SheenColorIsSrgbAndRoughnessLinear) {
    const Scene s = load("sheen.gltf", R"([{"extensions": {"KHR_materials_sheen": {
        "sheenColorFactor": [0.9, 0.5, 0.1], "sheenColorTexture": {"index": 0},
        "sheenRoughnessFactor": 0.4, "sheenRoughnessTexture": {"index": 0}}}}])");
    const Material& m = s.materials.at(0);
    EXPECT_EQ(m.sheen_color, Color(0.9f, 0.5f, 0.1f));
    EXPECT_FLOAT_EQ(m.sheen_roughness, 0.4f);
    EXPECT_TRUE(srgb(s, m.sheen_color_texture));
    EXPECT_FALSE(srgb(s, m.sheen_roughness_texture));
    // The same glTF texture read both ways: two Scene textures.
    EXPECT_NE(m.sheen_color_texture.texture, m.sheen_roughness_texture.texture);
    EXPECT_TRUE(m.layered());
}

TEST(GltfMaterialExtensions, IridescenceKeepsAThicknessMinimumAboveTheMaximum) {
    const Scene s = load("iridescence.gltf", R"([{"extensions": {"KHR_materials_iridescence": {
        "iridescenceFactor": 0.75, "iridescenceTexture": {"index": 0}, "iridescenceIor": 1.8,
        "iridescenceThicknessMinimum": 500, "iridescenceThicknessMaximum": 120,
        "iridescenceThicknessTexture": {"index": 1, "texCoord": 1}}}}])");
    const Material& m = s.materials.at(0);
    EXPECT_FLOAT_EQ(m.iridescence, 0.75f);
    EXPECT_FLOAT_EQ(m.iridescence_ior, 1.8f);
    EXPECT_FLOAT_EQ(m.iridescence_thickness_min, 500.f);  // the extension allows minimum > maximum
    EXPECT_FLOAT_EQ(m.iridescence_thickness_max, 120.f);
    EXPECT_FALSE(srgb(s, m.iridescence_texture));
    EXPECT_FALSE(srgb(s, m.iridescence_thickness_texture));
    EXPECT_EQ(m.iridescence_thickness_texture.uv_set, 1u);
    // Kept, and said: one warning naming the field and both values.
    EXPECT_EQ(warnings_containing(s, "iridescenceThicknessMinimum: 500 nm above iridescenceThicknessMaximum 120"), 1u);
    EXPECT_EQ(warnings_containing(s, "thins where the thickness texture's green rises"), 1u);
}

TEST(GltfMaterialExtensions, AnisotropyDispersionAndDiffuseTransmission) {
    const Scene s = load("aniso_disp_dt.gltf", R"([{"extensions": {
        "KHR_materials_anisotropy": {"anisotropyStrength": 0.6, "anisotropyRotation": -1.57,
                                     "anisotropyTexture": {"index": 0}},
        "KHR_materials_dispersion": {"dispersion": 0.36},
        "KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 0.25,
            "diffuseTransmissionTexture": {"index": 1}, "diffuseTransmissionColorFactor": [1, 0.5, 0.25],
            "diffuseTransmissionColorTexture": {"index": 2}}}}])");
    const Material& m = s.materials.at(0);
    EXPECT_FLOAT_EQ(m.anisotropy_strength, 0.6f);
    EXPECT_FLOAT_EQ(m.anisotropy_rotation, -1.57f);  // any angle, not clamped
    EXPECT_FALSE(srgb(s, m.anisotropy_texture));
    EXPECT_FLOAT_EQ(m.dispersion, 0.36f);
    EXPECT_FLOAT_EQ(m.diffuse_transmission, 0.25f);
    EXPECT_EQ(m.diffuse_transmission_color, Color(1.f, 0.5f, 0.25f));
    EXPECT_FALSE(srgb(s, m.diffuse_transmission_texture));
    EXPECT_TRUE(srgb(s, m.diffuse_transmission_color_texture));
    EXPECT_EQ(warnings_containing(s, "clamped"), 0u);
}

TEST(GltfMaterialExtensions, AbsentOrEmptyExtensionsKeepTheDefaults) {
    const Material defaults;
    for (const char* materials : {R"([{}])", R"([{"extensions": {"KHR_materials_clearcoat": {},
        "KHR_materials_sheen": {}, "KHR_materials_iridescence": {}, "KHR_materials_anisotropy": {},
        "KHR_materials_dispersion": {}, "KHR_materials_diffuse_transmission": {}}}])"}) {
        SCOPED_TRACE(materials);
        const Scene s = load("defaults.gltf", materials);
        const Material& m = s.materials.at(0);
        EXPECT_EQ(m.clearcoat, 0.f);
        EXPECT_EQ(m.clearcoat_roughness, 0.f);
        EXPECT_FALSE(m.clearcoat_normal_texture.valid());
        EXPECT_EQ(m.sheen_color, Color(0.f));
        EXPECT_EQ(m.sheen_roughness, 0.f);
        EXPECT_EQ(m.iridescence, 0.f);
        EXPECT_EQ(m.iridescence_ior, 1.3f);
        EXPECT_EQ(m.iridescence_thickness_min, 100.f);
        EXPECT_EQ(m.iridescence_thickness_max, 400.f);
        EXPECT_EQ(m.anisotropy_strength, 0.f);
        EXPECT_EQ(m.anisotropy_rotation, 0.f);
        EXPECT_EQ(m.dispersion, 0.f);
        EXPECT_EQ(m.diffuse_transmission, 0.f);
        EXPECT_EQ(m.diffuse_transmission_color, Color(1.f));
        EXPECT_FALSE(m.specular_glossiness);
        EXPECT_EQ(m.metallic, defaults.metallic);
        EXPECT_EQ(m.roughness, defaults.roughness);
        EXPECT_FALSE(m.layered());
        EXPECT_TRUE(s.textures.empty());
        EXPECT_TRUE(s.meshes.at(0).tangents.empty());  // no tangent frame needed
    }
}

// ---- specular-glossiness ----------------------------------------------------------------------

TEST(GltfMaterialExtensions, SpecularGlossinessReplacesMetallicRoughness) {
    // The file gives both models: the extension wins, pbrMetallicRoughness and its textures are unused.
    const std::string path = quad_file("specgloss.gltf", R"([{"pbrMetallicRoughness": {
            "baseColorFactor": [0.1, 0.2, 0.3, 1], "metallicFactor": 1, "roughnessFactor": 0.05,
            "baseColorTexture": {"index": 3}, "metallicRoughnessTexture": {"index": 3}},
        "extensions": {"KHR_materials_pbrSpecularGlossiness": {
            "diffuseFactor": [0.5, 0.25, 0.125, 0.75], "diffuseTexture": {"index": 0, "texCoord": 1},
            "specularFactor": [1, 0.766, 0.336], "glossinessFactor": 0.9,
            "specularGlossinessTexture": {"index": 1}}}}])",
                                       R"(["KHR_materials_pbrSpecularGlossiness"])",
                                       R"(["KHR_materials_pbrSpecularGlossiness"])");
    const Scene s = load_scene(path, quick());  // required, and supported: it loads
    const Material& m = s.materials.at(0);
    EXPECT_TRUE(m.specular_glossiness);
    EXPECT_EQ(m.base_color, Vec4f(0.5f, 0.25f, 0.125f, 0.75f));
    EXPECT_TRUE(srgb(s, m.base_color_texture));
    EXPECT_EQ(m.base_color_texture.uv_set, 1u);
    EXPECT_EQ(m.sg_specular, Color(1.f, 0.766f, 0.336f));
    EXPECT_FLOAT_EQ(m.glossiness, 0.9f);
    EXPECT_TRUE(srgb(s, m.specular_glossiness_texture));  // RGB sRGB; the sampler keeps A linear
    EXPECT_EQ(m.metallic, 0.f);
    EXPECT_FLOAT_EQ(m.roughness, 1.f - 0.9f);
    EXPECT_FALSE(m.metallic_roughness_texture.valid());
    EXPECT_FALSE(m.layered());
    EXPECT_EQ(s.textures.size(), 2u);  // diffuse and specular-glossiness only, not texture 3
    ASSERT_EQ(s.extensions.size(), 1u);
    EXPECT_EQ(s.extensions[0].support, ExtensionSupport::Supported);
    EXPECT_TRUE(s.extensions[0].required);
}

TEST(GltfMaterialExtensions, SpecularGlossinessTextureDecodesRgbAsSrgbAndAlphaLinear) {
    ImportOptions decode = quick();
    decode.load_textures = true;
    const Scene s = load_scene(quad_file("specgloss_texels.gltf", R"([{"extensions": {
        "KHR_materials_pbrSpecularGlossiness": {"specularGlossinessTexture": {"index": 0}}}}])",
                                         "[]", "[]", {128, 128, 128, 128}),
                               decode);
    const TextureRef& ref = s.materials.at(0).specular_glossiness_texture;
    ASSERT_TRUE(ref.valid());
    const Vec4f texel = sample_texture(s.textures.at(size_t(ref.texture)), {0.5f, 0.5f}, 0.f);
    EXPECT_NEAR(texel.x, srgb8_to_linear(128), 1e-6f);  // specular: sRGB 128 is about 0.216
    EXPECT_NEAR(texel.x, 0.2158605f, 1e-4f);
    EXPECT_NEAR(texel.w, 128.f / 255.f, 1e-6f);          // glossiness: linear
}

TEST(GltfMaterialExtensions, SpecularGlossinessDefaults) {
    const Scene s = load("specgloss_defaults.gltf",
                         R"([{"pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.2, 0.3, 0.4]},
                              "extensions": {"KHR_materials_pbrSpecularGlossiness": {}}}])");
    const Material& m = s.materials.at(0);
    EXPECT_TRUE(m.specular_glossiness);
    EXPECT_EQ(m.base_color, Vec4f(1.f, 1.f, 1.f, 1.f));
    EXPECT_EQ(m.sg_specular, Color(1.f));
    EXPECT_EQ(m.glossiness, 1.f);
    EXPECT_EQ(m.metallic, 0.f);
    EXPECT_EQ(m.roughness, 0.f);
    EXPECT_FALSE(m.base_color_texture.valid());
}

// ---- clamping and errors ----------------------------------------------------------------------

TEST(GltfMaterialExtensions, OutOfRangeFactorsAreClampedWithOneWarningEach) {
    const Scene s = load("clamped.gltf", R"([{"extensions": {
        "KHR_materials_clearcoat": {"clearcoatFactor": 1.5, "clearcoatRoughnessFactor": -0.5},
        "KHR_materials_sheen": {"sheenColorFactor": [2, 0.5, -1], "sheenRoughnessFactor": 3},
        "KHR_materials_iridescence": {"iridescenceFactor": 7},
        "KHR_materials_anisotropy": {"anisotropyStrength": 1.25},
        "KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": -1,
                                               "diffuseTransmissionColorFactor": [1.5, 1, 1]}}},
      {"extensions": {"KHR_materials_pbrSpecularGlossiness": {"diffuseFactor": [1, 1, 1.5, 2],
          "specularFactor": [0, -0.25, 1], "glossinessFactor": 1.2}}},
      {"extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 2}}}])");
    const Material& m = s.materials.at(0);
    EXPECT_EQ(m.clearcoat, 1.f);
    EXPECT_EQ(m.clearcoat_roughness, 0.f);
    EXPECT_EQ(m.sheen_color, Color(1.f, 0.5f, 0.f));
    EXPECT_EQ(m.sheen_roughness, 1.f);
    EXPECT_EQ(m.iridescence, 1.f);
    EXPECT_EQ(m.anisotropy_strength, 1.f);
    EXPECT_EQ(m.diffuse_transmission, 0.f);
    EXPECT_EQ(m.diffuse_transmission_color, Color(1.f));
    const Material& sg = s.materials.at(1);
    EXPECT_EQ(sg.base_color, Vec4f(1.f, 1.f, 1.f, 1.f));
    EXPECT_EQ(sg.sg_specular, Color(0.f, 0.f, 1.f));
    EXPECT_EQ(sg.glossiness, 1.f);
    EXPECT_EQ(sg.roughness, 0.f);
    EXPECT_EQ(s.materials.at(2).clearcoat, 1.f);

    // One warning per (material, field), naming it and what was clamped; a field with several
    // components out of range still gives one.
    const std::string sheen = "/materials/0/extensions/KHR_materials_sheen/sheenColorFactor: ";
    EXPECT_EQ(warnings_containing(s, sheen), 1u);
    EXPECT_EQ(warnings_containing(s, sheen + "(2, 0.5, -1) outside [0, 1], clamped to (1, 0.5, 0)"), 1u);
    EXPECT_EQ(warnings_containing(s, "/materials/0/extensions/KHR_materials_clearcoat/clearcoatFactor: 1.5 "
                                     "outside [0, 1], clamped to 1"),
              1u);
    EXPECT_EQ(warnings_containing(s, "/materials/2/extensions/KHR_materials_clearcoat/clearcoatFactor: 2 "),
              1u);
    EXPECT_EQ(warnings_containing(s, "/materials/1/extensions/KHR_materials_pbrSpecularGlossiness/diffuseFactor: "),
              1u);
    // 8 fields of material 0, 3 of material 1, 1 of material 2.
    EXPECT_EQ(warnings_containing(s, "clamped to"), 12u);
}

TEST(GltfMaterialExtensions, MissingTextureInAnExtensionSlotIsALocatedError) {
    const std::string missing = quad_file("missing_texture.gltf", R"([{"extensions": {"KHR_materials_clearcoat":
        {"clearcoatFactor": 1, "clearcoatNormalTexture": {"index": 9}}}}])");
    expect_located_error([&] { load_scene(missing, quick()); }, "missing_texture.gltf",
                         "/materials/0/extensions/KHR_materials_clearcoat/clearcoatNormalTexture/index");
    const std::string negative = quad_file("negative_texture.gltf", R"([{"extensions": {"KHR_materials_sheen":
        {"sheenColorFactor": [1, 1, 1], "sheenColorTexture": {"index": -1}}}}])");
    expect_located_error([&] { load_scene(negative, quick()); }, "negative_texture.gltf",
                         "/materials/0/extensions/KHR_materials_sheen/sheenColorTexture/index");
    const std::string sg = quad_file("missing_sg_texture.gltf", R"([{"extensions": {
        "KHR_materials_pbrSpecularGlossiness": {"specularGlossinessTexture": {"index": 4}}}}])");
    expect_located_error([&] { load_scene(sg, quick()); }, "missing_sg_texture.gltf",
                         "/materials/0/extensions/KHR_materials_pbrSpecularGlossiness/specularGlossinessTexture/index");
}

TEST(GltfMaterialExtensions, InvalidValuesAreLocatedErrors) {
    struct Case {
        const char* materials;
        const char* pointer;
    };
    const Case cases[] = {
        {R"([{"extensions": {"KHR_materials_dispersion": {"dispersion": -0.1}}}])",
         "/materials/0/extensions/KHR_materials_dispersion/dispersion"},
        {R"([{"extensions": {"KHR_materials_iridescence": {"iridescenceIor": 0}}}])",
         "/materials/0/extensions/KHR_materials_iridescence/iridescenceIor"},
        {R"([{"extensions": {"KHR_materials_iridescence": {"iridescenceThicknessMinimum": -5}}}])",
         "/materials/0/extensions/KHR_materials_iridescence/iridescenceThicknessMinimum"},
        {R"([{"extensions": {"KHR_materials_iridescence": {"iridescenceThicknessMaximum": -1}}}])",
         "/materials/0/extensions/KHR_materials_iridescence/iridescenceThicknessMaximum"},
        {R"([{}, {"extensions": {"KHR_materials_sheen": {"sheenColorFactor": [1, 1]}}}])",
         "/materials/1/extensions/KHR_materials_sheen/sheenColorFactor"},
        {R"([{"extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": "1"}}}])",
         "/materials/0/extensions/KHR_materials_clearcoat/clearcoatFactor"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.materials);
        const std::string path = quad_file("invalid_value.gltf", c.materials);
        expect_located_error([&] { load_scene(path, quick()); }, "invalid_value.gltf", c.pointer);
    }
}

TEST(GltfMaterialExtensions, NonFiniteFactorIsAnErrorNamingTheFile) {
    // JSON has no NaN or infinity: a factor that overflows a double is refused while parsing, so
    // the message names the file and the offending number rather than a pointer.
    const std::string path = quad_file("non_finite.gltf", R"([{"extensions": {"KHR_materials_clearcoat":
        {"clearcoatFactor": 1e999}}}])");
    std::string message;
    try {
        load_scene(path, quick());
    } catch (const std::exception& e) {
        message = e.what();
    }
    ASSERT_FALSE(message.empty());
    EXPECT_NE(message.find("non_finite.gltf"), std::string::npos) << message;
    EXPECT_NE(message.find("1e999"), std::string::npos) << message;
}

// ---- tangents ---------------------------------------------------------------------------------

TEST(GltfMaterialExtensions, AnisotropyAndCoatNormalMapsGetGeneratedTangents) {
    struct Case {
        const char* materials;
        Vec3f tangent;  ///< (0, 0, 0): no tangents expected
    };
    const Case cases[] = {
        // Anisotropy without a texture: TEXCOORD_0 (+X).
        {R"([{"extensions": {"KHR_materials_anisotropy": {"anisotropyStrength": 0.5}}}])", {1, 0, 0}},
        // The anisotropy texture's UV set.
        {R"([{"extensions": {"KHR_materials_anisotropy": {"anisotropyStrength": 0.5,
             "anisotropyTexture": {"index": 0, "texCoord": 1}}}}])", {0, 1, 0}},
        // The normal texture's UV set wins over the anisotropy texture's.
        {R"([{"normalTexture": {"index": 1}, "extensions": {"KHR_materials_anisotropy": {"anisotropyStrength": 1,
             "anisotropyTexture": {"index": 0, "texCoord": 1}}}}])", {1, 0, 0}},
        // A clearcoat normal map, through KHR_texture_transform's texCoord.
        {R"([{"extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1, "clearcoatNormalTexture":
             {"index": 0, "extensions": {"KHR_texture_transform": {"texCoord": 1}}}}}}])", {0, 1, 0}},
        // Strength 0 or a coat of factor 0: no layer, no tangents.
        {R"([{"extensions": {"KHR_materials_anisotropy": {"anisotropyStrength": 0,
             "anisotropyTexture": {"index": 0}}}}])", {0, 0, 0}},
        {R"([{"extensions": {"KHR_materials_clearcoat": {"clearcoatNormalTexture": {"index": 0}}}}])", {0, 0, 0}},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.materials);
        const Scene s = load("tangents.gltf", c.materials);
        const std::vector<Vec4f>& t = s.meshes.at(0).tangents;
        if (c.tangent == Vec3f(0.f)) {
            EXPECT_TRUE(t.empty());
            continue;
        }
        ASSERT_EQ(t.size(), 4u);
        for (const Vec4f& v : t) EXPECT_VEC3_NEAR(v.xyz(), c.tangent.x, c.tangent.y, c.tangent.z, 1e-6f);
    }
}

TEST(GltfMaterialExtensions, AnisotropyWithoutTheUvSetWarns) {
    // The anisotropy texture asks for TEXCOORD_1 on a primitive that has TEXCOORD_0 only.
    const std::vector<uint8_t> bytes = read_bytes(quad_file("aniso_no_uv.gltf", R"([{"extensions": {
        "KHR_materials_anisotropy": {"anisotropyStrength": 1, "anisotropyTexture": {"index": 0, "texCoord": 1}}}}])"));
    std::string json(bytes.begin(), bytes.end());
    const std::string uv1 = R"(, "TEXCOORD_1": 3})";
    ASSERT_NE(json.find(uv1), std::string::npos);
    json.replace(json.find(uv1), uv1.size(), "}");
    const Scene s = load_scene(write_file("aniso_no_uv.gltf", json), quick());
    EXPECT_TRUE(s.meshes.at(0).tangents.empty());
    EXPECT_EQ(warnings_containing(s, "/meshes/0/primitives/0: the anisotropy texture uses TEXCOORD_1, which the "
                                     "primitive lacks: no tangents, anisotropy has no direction"),
              1u);
}

// ---- Khronos samples --------------------------------------------------------------------------

TEST(GltfMaterialExtensions, ClearCoatTestSample) {
    const Scene s = load_scene(asset("ClearCoatTest/glTF-Binary/ClearCoatTest.glb"), quick());
    const auto coated = std::count_if(s.materials.begin(), s.materials.end(),
                                      [](const Material& m) { return m.clearcoat > 0.f; });
    EXPECT_EQ(coated, 6);
    // The coat normal maps: linear textures, and every mesh using one has a tangent frame.
    size_t coat_normal_meshes = 0;
    for (const Mesh& mesh : s.meshes) {
        const Material& m = s.materials.at(mesh.material);
        if (m.clearcoat <= 0.f || !m.clearcoat_normal_texture.valid()) continue;
        ++coat_normal_meshes;
        EXPECT_FALSE(srgb(s, m.clearcoat_normal_texture));
        EXPECT_EQ(mesh.tangents.size(), mesh.positions.size()) << mesh.name;
    }
    EXPECT_GT(coat_normal_meshes, 0u);
}

TEST(GltfMaterialExtensions, AnisotropyRotationTestSample) {
    const Scene s = load_scene(asset("AnisotropyRotationTest/glTF-Binary/AnisotropyRotationTest.glb"), quick());
    std::vector<float> rotations;
    for (const Material& m : s.materials)
        if (m.anisotropy_strength > 0.f) rotations.push_back(m.anisotropy_rotation);
    ASSERT_EQ(rotations.size(), 4u);
    EXPECT_NE(std::find_if(rotations.begin(), rotations.end(),
                           [](float r) { return std::abs(r - 0.523599f) < 1e-5f; }),  // 30 degrees
              rotations.end());
    for (const Mesh& mesh : s.meshes) {
        if (s.materials.at(mesh.material).anisotropy_strength > 0.f) {
            EXPECT_EQ(mesh.tangents.size(), mesh.positions.size()) << mesh.name;
        }
    }
}

// ---- whitted info -----------------------------------------------------------------------------

TEST(GltfMaterialExtensions, InfoListsActiveExtensionsOnly) {
    const std::string path = quad_file("info.gltf", R"([{"extensions": {
        "KHR_materials_clearcoat": {"clearcoatFactor": 1, "clearcoatRoughnessFactor": 0.1},
        "KHR_materials_sheen": {"sheenColorFactor": [1, 0.5, 0], "sheenRoughnessFactor": 0.25},
        "KHR_materials_dispersion": {"dispersion": 0}}},
      {"extensions": {"KHR_materials_pbrSpecularGlossiness": {"specularFactor": [0.5, 0.5, 0.5],
                                                               "glossinessFactor": 0.75}}},
      {"extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 0}}}])",
                                       R"(["KHR_materials_clearcoat", "KHR_materials_sheen"])");
    const std::string text = describe_scene(load_scene(path, quick()));
    EXPECT_NE(text.find("\nmaterial[0] extensions: clearcoat=1 roughness=0.1; sheen color=(1, 0.5, 0) "
                        "roughness=0.25\n"),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("\nmaterial[1] extensions: specular-glossiness specular=(0.5, 0.5, 0.5) glossiness=0.75\n"),
              std::string::npos)
        << text;
    EXPECT_EQ(text.find("material[2] extensions:"), std::string::npos) << text;  // clearcoat 0: inactive
    EXPECT_NE(text.find("\nextension: KHR_materials_clearcoat supported required=no"), std::string::npos) << text;
    EXPECT_EQ(text.find("extension KHR_materials_sheen ignored"), std::string::npos) << text;
}

}  // namespace
}  // namespace whitted::test
