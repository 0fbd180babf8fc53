// KHR_materials_variants (docs/gltf-support.md "Material variants"): a hand-made file of two
// primitives and three materials, one primitive mapped per variant, the other only for one; the
// default materials without a variant; the variants recorded for `whitted info`; a scene file's
// include naming one; and each bad input one error naming the file and what is wrong.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <fmt/format.h>

#include "importers/scene_loader.h"
#include "importers/scene_report.h"
#include "tests/support/test_importer_util.h"

namespace whitted {
namespace {

using namespace whitted::test;

/// Two triangles ("a" uses material 0 "red", "b" material 1 "green") and material 2 "blue";
/// variants "plain" and "fancy": a -> blue under "fancy"; b -> red under "plain" and "fancy".
/// `mapping_a` replaces a's mappings JSON.
std::vector<uint8_t> variants_file(const std::string& mapping_a = R"([{"material":2,"variants":[1]}])") {
    Bytes bin;
    for (int k = 0; k < 2; ++k) bin.put<float>({0, 0, float(k), 1, 0, float(k), 0, 1, float(k)});
    const std::string json = fmt::format(R"({{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1]}}],
        "extensionsUsed":["KHR_materials_variants"],
        "extensions":{{"KHR_materials_variants":{{"variants":[{{"name":"plain"}},{{"name":"fancy"}}]}}}},
        "nodes":[{{"name":"a","mesh":0}},{{"name":"b","mesh":1}}],
        "materials":[{{"name":"red"}},{{"name":"green"}},{{"name":"blue"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"material":0,
                     "extensions":{{"KHR_materials_variants":{{"mappings":{}}}}}}}]}},
                  {{"primitives":[{{"attributes":{{"POSITION":1}},"material":1,
                     "extensions":{{"KHR_materials_variants":{{"mappings":[{{"material":0,"variants":[0,1]}}]}}}}}}]}}],
        "buffers":[{{"byteLength":72}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                     {{"bufferView":1,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,1],"max":[1,1,1]}}]}})",
                                         mapping_a);
    return make_glb(json, bin.data);
}

/// `fn` must throw whitted::Error: one line naming `file` and holding every one of `parts`.
template <typename F>
void expect_error(F&& fn, const std::string& file, const std::vector<std::string>& parts) {
    const std::string e = error_text(fn);
    ASSERT_FALSE(e.empty()) << "no whitted::Error; expected one about " << parts.front();
    EXPECT_NE(e.find(file), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    for (const std::string& p : parts) EXPECT_NE(e.find(p), std::string::npos) << "'" << p << "' missing from: " << e;
}

Scene import(const std::vector<uint8_t>& glb, const std::string& variant) {
    ImportOptions o = no_textures();
    o.variant = variant;
    return import_gltf_memory(glb, "shoe.glb", o);
}

/// The material name of the instance of node `node`.
std::string material_of(const Scene& s, const std::string& node) {
    for (const Instance& i : s.instances)
        if (i.node_name == node) return s.materials[s.meshes[i.mesh].material].name;
    ADD_FAILURE() << "no node " << node;
    return "";
}

TEST(GltfVariants, DefaultMaterialsWithoutAVariant) {
    const Scene s = import(variants_file(), "");
    EXPECT_EQ(material_of(s, "a"), "red");
    EXPECT_EQ(material_of(s, "b"), "green");
    EXPECT_EQ(s.variants, (std::vector<std::string>{"plain", "fancy"}));
    EXPECT_EQ(s.variant, "");
}

TEST(GltfVariants, AVariantMapsOnlyThePrimitivesThatListIt) {
    const Scene plain = import(variants_file(), "plain");
    EXPECT_EQ(material_of(plain, "a"), "red");  // a has no mapping for "plain": its own material
    EXPECT_EQ(material_of(plain, "b"), "red");
    const Scene fancy = import(variants_file(), "fancy");
    EXPECT_EQ(material_of(fancy, "a"), "blue");
    EXPECT_EQ(material_of(fancy, "b"), "red");
    EXPECT_EQ(fancy.variant, "fancy");
    const std::string report = describe_scene(fancy, ReportDetail::Summary);
    EXPECT_NE(report.find("variant[1]: name=\"fancy\" applied=yes"), std::string::npos) << report;
    EXPECT_NE(report.find("variant[0]: name=\"plain\" applied=no"), std::string::npos) << report;
}

TEST(GltfVariants, UnknownNameListsTheVariants) {
    expect_error([] { import(variants_file(), "gold"); }, "shoe.glb",
                 {"no variant 'gold'", "'plain', 'fancy'", "/extensions/KHR_materials_variants/variants"});
}

TEST(GltfVariants, BadMappingsNameTheirPointer) {
    expect_error([] { import(variants_file(R"([{"material":7,"variants":[1]}])"), "fancy"); }, "shoe.glb",
                 {"/meshes/0/primitives/0/extensions/KHR_materials_variants/mappings/0/material", "3 materials"});
    expect_error([] { import(variants_file(R"([{"material":2,"variants":[5]}])"), "fancy"); }, "shoe.glb",
                 {"mappings/0/variants/0", "2 variants"});
}

TEST(GltfVariants, AFileWithoutVariantsOrASceneFileRefusesOne) {
    const std::string box = std::string(WHITTED_ASSETS_DIR) + "/gltf/Box/glTF-Binary/Box.glb";
    ImportOptions o = no_textures();
    o.variant = "fancy";
    expect_error([&] { load_scene(box, o); }, "Box.glb", {"variant 'fancy'", "no KHR_materials_variants variants"});
    const std::string scene = write_file("variant_scene.json", R"({"version":1,"include":[{"file":"x.glb"}]})");
    expect_error([&] { load_scene(scene, o); }, "variant_scene.json", {"scene file has no variants", "include"});
}

TEST(GltfVariants, ASceneFileIncludeNamesAVariant) {
    write_file("variants_shoe.glb", variants_file());
    const std::string scene = write_file(
        "variants_scene.json", R"({"version":1,"include":[{"file":"variants_shoe.glb","variant":"fancy"}]})");
    const Scene s = load_scene(scene, no_textures());
    EXPECT_EQ(material_of(s, "a"), "blue");
    EXPECT_EQ(material_of(s, "b"), "red");
}

}  // namespace
}  // namespace whitted
