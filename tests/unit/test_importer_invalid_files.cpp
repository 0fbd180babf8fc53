// Every file of tests/data/gltf-invalid (glTF-Validator and tinygltf test cases): the broken ones
// are rejected with one whitted::Error naming the file and the problem (and the JSON pointer
// where whitted can locate it); the valid edge cases load.

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/support/test_importer_util.h"

namespace whitted::test {
namespace {

struct InvalidCase {
    const char* file;                   ///< relative to tests/data/gltf-invalid
    bool loads;                         ///< true for the valid edge cases
    std::vector<const char*> expected;  ///< substrings of the error text, or of one warning when it loads
};

// The pointer and wording come from whitted's own validation where it gets that far; tinygltf
// rejects some files first (its message is kept, prefixed with the file).
const std::vector<InvalidCase> kCases = {
    // tinygltf's BoundsChecking models: "expected to fail, but not crash".
    {"tinygltf/BoundsChecking/integer-out-of-bounds.gltf", false, {"not a positive integer"}},
    {"tinygltf/BoundsChecking/invalid-buffer-index.gltf", false, {"image[0] buffer \"1\" not found"}},
    {"tinygltf/BoundsChecking/invalid-buffer-view-index.gltf", false, {"accessor[0] invalid bufferView"}},
    {"tinygltf/BoundsChecking/invalid-primitive-indices.gltf", false, {"primitive indices accessor out of bounds"}},
    {"tinygltf/regression/zero-sized-bin-chunk-issue-440.glb", true, {}},
    // glTF-Validator cases. The two accessor files also lack a buffer uri in a .gltf, which
    // tinygltf refuses before whitted sees their stride / sparse problems.
    {"validator/accessor/invalid_sparse_count_and_stride.gltf", false, {"buffer has no uri"}},
    {"validator/accessor/small_stride.gltf", false, {"buffer has no uri"}},
    {"validator/accessor_data/out_of_range_elements_float.gltf",
     false,
     {"/accessors/0/min/0", "outside the declared minimum"}},
    {"validator/asset/1_0_version.gltf", false, {"/asset/version", "'1.0'"}},
    {"validator/buffer/invalid_uri_data.gltf", false, {"invalid data URI", "data:application/octet-stream;;base64"}},
    {"validator/buffer/no_bin_chunk.glb", false, {"empty BIN chunk"}},
    {"validator/buffer/not_found.gltf", false, {"missing resource 'not_found.bin'"}},
    {"validator/buffer_view/invalid_length.gltf",
     false,
     {"/bufferViews/0/byteLength", "does not fit buffer 0 (4 bytes)"}},
    {"validator/buffer_view/invalid_stride_too_big.gltf",
     false,
     {"/bufferViews/0/byteStride", "greater than byteLength"}},
    {"validator/camera/infinite_znear.gltf", false, {"invalid JSON", "1e309"}},
    {"validator/glb/invalid_magic.glb", false, {"invalid GLB magic"}},
    {"validator/glb/truncated_chunk_data.glb", false, {"truncated GLB", "48 bytes", "has 47"}},
    {"validator/image/not_found.gltf", false, {"/images/0/uri", "'not_found.png' not found"}},
    {"validator/json/bom.gltf", false, {"byte order mark"}},
    {"validator/json/empty_file.gltf", false, {"empty file"}},
    {"validator/json/invalid_syntax.gltf", false, {"invalid JSON"}},
    {"validator/material/unresolved_basecolor.gltf",
     false,
     {"/materials/0/pbrMetallicRoughness/baseColorTexture/index", "texture 0 does not exist"}},
    {"validator/mesh/accessor_unequal_count.gltf",
     false,
     {"/meshes/0/primitives/0/attributes/COLOR_0", "same count", "has 4, expected 3"}},
    {"validator/mesh/primitive_incompatible_mode.gltf", true, {"/meshes/0/primitives/0", "not a multiple of 3"}},
    {"validator/mesh/primitive_no_position.gltf", true, {"/meshes/0/primitives/0", "no POSITION"}},
    {"validator/mesh/unresolved_indices.gltf", false, {"primitive indices accessor out of bounds"}},
    {"validator/mesh_data/index_buffer_degenerate_triangle.gltf", true, {}},
    {"validator/mesh_data/index_buffer_oob.gltf",
     false,
     {"/meshes/0/primitives/0/indices", "index value 5", "vertex count 4"}},
    {"validator/node/node_loop.gltf", false, {"/nodes/0", "node loop"}},
    {"validator/scene/unresolved_node.gltf", false, {"/scenes/0/nodes/0", "node 0 does not exist"}},
};

TEST(GltfInvalidFiles, EachCaseThrowsOrLoadsAsExpected) {
    for (const InvalidCase& c : kCases) {
        SCOPED_TRACE(c.file);
        const std::string path = invalid_file(c.file);
        if (c.loads) {
            Scene scene;
            ASSERT_NO_THROW(scene = load_scene(path)) << error_text([&] { load_scene(path); });
            EXPECT_FALSE(scene.materials.empty());
            for (const char* s : c.expected) {
                const bool found = std::any_of(scene.warnings.begin(), scene.warnings.end(),
                                               [&](const std::string& w) { return w.find(s) != std::string::npos; });
                EXPECT_TRUE(found) << "no warning contains '" << s << "'";
            }
            continue;
        }
        const std::string text = error_text([&] { load_scene(path); });
        ASSERT_FALSE(text.empty()) << "expected whitted::Error";
        EXPECT_NE(text.find(path), std::string::npos) << "error does not name the file: " << text;
        EXPECT_EQ(text.find('\n'), std::string::npos) << "error is not one line: " << text;
        for (const char* s : c.expected) EXPECT_NE(text.find(s), std::string::npos) << "'" << s << "' not in: " << text;
    }
}

TEST(GltfInvalidFiles, TableCoversEveryFile) {
    // A file added to tests/data/gltf-invalid without an expected outcome fails here.
    const std::filesystem::path root = invalid_file("");
    size_t models = 0;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
        const std::string ext = entry.path().extension().string();
        if (ext != ".gltf" && ext != ".glb") continue;
        ++models;
        const std::string rel = std::filesystem::relative(entry.path(), root).string();
        const bool listed =
            std::any_of(kCases.begin(), kCases.end(), [&](const InvalidCase& c) { return rel == c.file; });
        EXPECT_TRUE(listed) << rel << " has no entry in kCases";
    }
    EXPECT_EQ(models, kCases.size());
}

TEST(GltfInvalidFiles, ValidEdgeCasesLoadTheirGeometry) {
    // zero-sized-bin-chunk: one triangle, node 0 in scene 0.
    const Scene glb = load_scene(invalid_file("tinygltf/regression/zero-sized-bin-chunk-issue-440.glb"));
    EXPECT_EQ(glb.instanced_triangle_count(), 1u);
    ASSERT_EQ(glb.materials.size(), 1u);
    EXPECT_FLOAT_EQ(glb.materials[0].base_color.y, 0.9f);
    EXPECT_TRUE(glb.materials[0].double_sided);
    // The validator files have no scene: nothing is placed, the file still loads with defaults.
    const Scene degenerate = load_scene(invalid_file("validator/mesh_data/index_buffer_degenerate_triangle.gltf"));
    EXPECT_EQ(degenerate.instances.size(), 0u);
    EXPECT_EQ(degenerate.cameras.size(), 1u);
    EXPECT_TRUE(degenerate.cameras[0].is_default);
}

}  // namespace
}  // namespace whitted::test
