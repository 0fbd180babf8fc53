// libFuzzer harness: texture images through whitted's texture path: the header check, decoding
// to RGBA8 (stb_image via tinygltf, as the importer does), the MIP chain, and a few lookups.
#include <cstddef>
#include <cstdint>

#include "importers/image_decode.h"
#include "core/error.h"
#include "shading/texture_sampling.h"

namespace {

constexpr size_t kMaxMemory = size_t(256) << 20;  ///< as fuzz_common.h: under libFuzzer's RSS limit

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace whitted;
    try {
        Texture texture;
        texture.name = "fuzz";
        texture.srgb = size % 2 == 0;  // both transfer functions, chosen by the input
        texture.levels.assign(1, decode_image_rgba8(data, size, kMaxMemory, FileLoc{"input", "/images/0"}, "input"));
        build_mip_levels(texture);
        for (float lod : {0.f, 1.5f, 100.f})
            for (Vec2f uv : {Vec2f(0.f, 0.f), Vec2f(0.5f, 0.5f), Vec2f(-1.25f, 7.75f), Vec2f(0.999f, 1e-7f)})
                (void)sample_texture(texture, uv, lod);
    } catch (const Error&) {
        // Refused or undecodable: the expected outcome for broken input.
    }
    return 0;
}
