// libFuzzer harness: the glTF importer on .gltf (JSON) bytes, through tinygltf, validation,
// traversal, geometry and texture decoding (images from data: URIs). See docs/fuzzing.md.
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    whitted::fuzz::import_bytes(data, size, "input.gltf");
    return 0;
}
