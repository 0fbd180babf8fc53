// Replays every input under tests/data/fuzz-regressions/ through the code of its fuzz harness
// (docs/fuzzing.md): each must import or end in whitted::Error, never crash or throw anything
// else (run under the ASan+UBSan build in CI, where a memory error fails the test). Then the
// limits on hostile input: URI policy, image header dimensions, JSON nesting, instance counts.
#include <algorithm>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "importers/image_decode.h"
#include "importers/scene_report.h"
#include "shading/texture_sampling.h"
#include "tests/support/test_importer_util.h"

namespace whitted {
namespace {

using namespace whitted::test;
namespace fs = std::filesystem;

constexpr size_t kFuzzMaxMemory = size_t(256) << 20;  ///< as fuzz/fuzz_common.h

fs::path regressions_dir() { return fs::path(WHITTED_TEST_DATA_DIR) / "fuzz-regressions"; }

std::vector<fs::path> regression_files(const std::string& harness) {
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(regressions_dir() / harness, ec))
        if (e.is_regular_file() && e.path().extension() != ".md") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
}

/// What fuzz_gltf / fuzz_glb do with one input, minus libFuzzer.
void replay_import(const std::vector<uint8_t>& bytes, const std::string& name) {
    ImportOptions options;
    options.max_memory = kFuzzMaxMemory;
    try {
        const Scene scene = import_gltf_memory(bytes, "/nonexistent-whitted-fuzz/" + name, options);
        (void)describe_scene(scene);
    } catch (const Error&) {
    }
}

/// What fuzz_image does with one input.
void replay_image(const std::vector<uint8_t>& bytes) {
    try {
        Texture texture;
        texture.srgb = bytes.size() % 2 == 0;
        texture.levels.assign(1, decode_image_rgba8(bytes.data(), bytes.size(), kFuzzMaxMemory,
                                                    FileLoc{"input", "/images/0"}, "input"));
        build_mip_levels(texture);
        for (float lod : {0.f, 1.5f, 100.f})
            for (Vec2f uv : {Vec2f(0.f, 0.f), Vec2f(0.5f, 0.5f), Vec2f(-1.25f, 7.75f), Vec2f(0.999f, 1e-7f)})
                (void)sample_texture(texture, uv, lod);
    } catch (const Error&) {
    }
}

TEST(FuzzRegressions, GltfInputsImportOrFailCleanly) {
    for (const fs::path& f : regression_files("gltf")) {
        SCOPED_TRACE(f.string());
        EXPECT_NO_THROW(replay_import(read_bytes(f.string()), "input.gltf"));
    }
}

TEST(FuzzRegressions, GlbInputsImportOrFailCleanly) {
    for (const fs::path& f : regression_files("glb")) {
        SCOPED_TRACE(f.string());
        EXPECT_NO_THROW(replay_import(read_bytes(f.string()), "input.glb"));
    }
}

TEST(FuzzRegressions, ImageInputsDecodeOrFailCleanly) {
    for (const fs::path& f : regression_files("image")) {
        SCOPED_TRACE(f.string());
        EXPECT_NO_THROW(replay_image(read_bytes(f.string())));
    }
}

// ---- limits on hostile input (docs/fuzzing.md "Limits") -------------------------------------

const std::string kAsset = R"("asset":{"version":"2.0"})";

/// A glTF whose only buffer is the external file `uri` (4 bytes).
std::string gltf_with_buffer_uri(const std::string& uri) {
    return "{" + kAsset + R"(,"buffers":[{"uri":")" + uri + R"(","byteLength":4}]})";
}

TEST(HostileInput, UriLeavingTheFolderIsRefusedUnlessAllowed) {
    fs::create_directories(scratch_dir() / "uri" / "inner");
    write_file("uri/outside.bin", std::string("abcd"));
    write_file("uri/inner/inside.bin", std::string("abcd"));
    const std::string up = write_file("uri/inner/up.gltf", gltf_with_buffer_uri("../outside.bin"));
    const std::string hidden = write_file("uri/inner/hidden.gltf", gltf_with_buffer_uri("x/%2e%2e/%2e%2e/outside.bin"));
    const std::string here = write_file("uri/inner/here.gltf", gltf_with_buffer_uri("./sub/../inside.bin"));

    EXPECT_NO_THROW(import_gltf(here));
    for (const std::string& path : {up, hidden}) {
        SCOPED_TRACE(path);
        const std::string e = error_text([&] { import_gltf(path); });
        EXPECT_NE(e.find("leaves the folder of the glTF file"), std::string::npos) << e;
        EXPECT_NE(e.find("--allow-outside-uris"), std::string::npos) << e;
        ImportOptions allow;
        allow.allow_outside_uris = true;
        EXPECT_NO_THROW(import_gltf(path, allow));
    }
}

TEST(HostileInput, AbsoluteAndSchemeUrisAreAlwaysRefused) {
    ImportOptions allow;
    allow.allow_outside_uris = true;
    const std::string target = write_file("absolute_target.bin", std::string("abcd"));
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"file://" + target, "'file:' URIs are not read"},
        {"file:///etc/passwd", "'file:' URIs are not read"},
        {"http://example.com/a.bin", "'http:' URIs are not read"},
        {target, "absolute paths are not read"},
        {"%2Fetc%2Fpasswd", "absolute paths are not read"},
        {"file%3A%2F%2F%2Fetc%2Fpasswd", "'file:' URIs are not read"},
        {"inside.bin%00.png", "NUL byte"},
    };
    for (const auto& [uri, expected] : cases) {
        SCOPED_TRACE(uri);
        const std::string path = write_file("scheme.gltf", gltf_with_buffer_uri(uri));
        const std::string e = error_text([&] { import_gltf(path, allow); });
        EXPECT_NE(e.find(expected), std::string::npos) << e;
    }
}

TEST(HostileInput, ResourcesThatAreNotRegularFilesAreRefused) {
    ImportOptions allow;
    allow.allow_outside_uris = true;
    fs::create_directories(scratch_dir() / "a_folder.bin");
    const std::string folder = write_file("folder.gltf", gltf_with_buffer_uri("a_folder.bin"));
    EXPECT_NE(error_text([&] { import_gltf(folder, allow); }).find("not a regular file"), std::string::npos);
}

/// A PNG signature and IHDR declaring width x height, and nothing else.
std::vector<uint8_t> png_header(uint32_t width, uint32_t height) {
    std::vector<uint8_t> png = make_png(1, 1, 8, 6, {0, 1, 2, 3, 4});
    for (int k = 0; k < 4; ++k) {
        png[16 + size_t(k)] = uint8_t(width >> (24 - 8 * k));
        png[20 + size_t(k)] = uint8_t(height >> (24 - 8 * k));
    }
    return png;
}

TEST(HostileInput, ImageDimensionsAreCheckedFromTheHeaderBeforeDecoding) {
    const std::vector<uint8_t> huge = png_header(100000, 100000);
    const std::string gltf = "{" + kAsset + R"(,"images":[{"uri":")" + data_uri(huge, "image/png") + R"("}]})";
    const std::string path = write_file("huge_image.gltf", gltf);
    const std::string e = error_text([&] { import_gltf(path); });
    EXPECT_NE(e.find("/images/0"), std::string::npos) << e;
    EXPECT_NE(e.find("100000x100000"), std::string::npos) << e;

    // The decoder entry point refuses it too, and a size under the side limit but over the memory limit.
    auto decode = [](const std::vector<uint8_t>& png) {
        return error_text([&] { decode_image_rgba8(png.data(), png.size(), kFuzzMaxMemory, {}, "x"); });
    };
    const std::string direct = decode(huge);
    EXPECT_NE(direct.find("32768 per side"), std::string::npos) << direct;
    const std::vector<uint8_t> big = png_header(30000, 30000);
    const std::string memory = decode(big);
    EXPECT_NE(memory.find("--max-memory"), std::string::npos) << memory;
    // A chunk declaring more bytes than the file holds is refused before stb_image sizes a buffer by it.
    const std::string chunk = decode(read_bytes((regressions_dir() / "image" / "oom-png-idat-length-2gib.png").string()));
    EXPECT_NE(chunk.find("truncated PNG: chunk 'IDAT'"), std::string::npos) << chunk;
    // A JPEG Huffman table of more than 256 codes (stb_image wrote past its table): libjpeg-turbo refuses it.
    const std::string huffman =
        decode(read_bytes((regressions_dir() / "image" / "ubsan-stbi-huffman-more-than-256-codes.jpg").string()));
    EXPECT_NE(huffman.find("corrupt JPEG"), std::string::npos) << huffman;
    // Every bundled JPEG still decodes (the check walks real files' segments and scans to the end).
    size_t jpegs = 0;
    for (const auto& e : fs::recursive_directory_iterator(fs::path(WHITTED_ASSETS_DIR) / "gltf")) {
        const std::string ext = e.path().extension().string();
        if (ext != ".jpg" && ext != ".jpeg") continue;
        const std::vector<uint8_t> jpeg = read_bytes(e.path().string());
        EXPECT_NO_THROW(decode_image_rgba8(jpeg.data(), jpeg.size(), size_t(1) << 30, {}, "x")) << e.path();
        ++jpegs;
    }
    EXPECT_GT(jpegs, 0u);
    const std::vector<uint8_t> gif = {'G', 'I', 'F', '8', '9', 'a', 1, 0, 1, 0, 0, 0, 0};
    const std::string other = decode(gif);
    EXPECT_NE(other.find("not a PNG, JPEG or WebP image"), std::string::npos) << other;
}

TEST(HostileInput, DeeplyNestedJsonIsRefusedBeforeParsing) {
    const std::string deep = "{" + kAsset + R"(,"extras":)" + std::string(100000, '[') + std::string(100000, ']') + "}";
    const std::vector<uint8_t> bytes(deep.begin(), deep.end());
    const std::string e = error_text([&] { import_gltf_memory(bytes, "deep.gltf"); });
    EXPECT_NE(e.find("nested deeper than"), std::string::npos) << e;
    // Brackets inside strings do not count.
    const std::string quoted = "{" + kAsset + R"(,"extras":")" + std::string(1000, '[') + "\"}";
    EXPECT_NO_THROW(import_gltf_memory(std::vector<uint8_t>(quoted.begin(), quoted.end()), "quoted.gltf"));
}

TEST(HostileInput, InstanceCountsAreBoundedByTheMemoryLimit) {
    // One triangle; a mesh of 200 primitives using it; 200 nodes placing the mesh: 40000 instances.
    Bytes b;
    b.put<float>({0, 0, 0, 1, 0, 0, 0, 1, 0});
    std::string prims, nodes, roots;
    for (int i = 0; i < 200; ++i) {
        prims += std::string(i ? "," : "") + R"({"attributes":{"POSITION":0}})";
        nodes += std::string(i ? "," : "") + R"({"mesh":0})";
        if (i) roots += ',';  // appended, not `"," + to_string(i)` (a -Wrestrict false positive)
        roots += std::to_string(i);
    }
    const std::string gltf = "{" + kAsset + R"(,"buffers":[{"uri":")" + data_uri(b.data) +
                             R"(","byteLength":36}],"bufferViews":[{"buffer":0,"byteLength":36}],)" +
                             R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)" +
                             R"("meshes":[{"primitives":[)" + prims + R"(]}],"nodes":[)" + nodes +
                             R"(],"scenes":[{"nodes":[)" + roots + "]}]}";
    const std::vector<uint8_t> bytes(gltf.begin(), gltf.end());
    ImportOptions small;
    small.max_memory = size_t(1) << 20;
    const std::string e = error_text([&] { import_gltf_memory(bytes, "instances.gltf", small); });
    EXPECT_NE(e.find("instances, more than the memory limit"), std::string::npos) << e;
    EXPECT_EQ(import_gltf_memory(bytes, "instances.gltf").instances.size(), 40000u);
}

TEST(HostileInput, FilesOverTheMemoryLimitAreRefusedBeforeReading) {
    const std::string path = write_file("big.gltf", "{" + kAsset + ",\"extras\":\"" + std::string(4096, 'x') + "\"}");
    ImportOptions tiny;
    tiny.max_memory = 1024;
    const std::string e = error_text([&] { import_gltf(path, tiny); });
    EXPECT_NE(e.find("exceeds the memory limit"), std::string::npos) << e;
}

}  // namespace
}  // namespace whitted
