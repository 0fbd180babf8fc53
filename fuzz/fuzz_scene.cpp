// libFuzzer harness: the JSON scene-file importer (docs/scene-format.md) on arbitrary bytes:
// JSON parsing with located errors, every object/material/light/camera/render key, geometry
// generation (boxes, rectangles, inline meshes) and validation. Includes and image files resolve
// into a folder that does not exist, so the harness never reads the file system through them.
#include "importers/scene_file.h"

#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const bool quiet = (whitted::set_log_level(whitted::LogLevel::Off), true);
    (void)quiet;
    whitted::ImportOptions options;
    options.max_memory = whitted::fuzz::kMaxMemory;
    try {
        const std::string_view text(reinterpret_cast<const char*>(data), size);
        const whitted::Scene scene =
            whitted::import_scene_file_text(text, whitted::fuzz::kFuzzFolder + "/input.json", options);
        (void)whitted::describe_scene(scene);
    } catch (const whitted::Error&) {
        // A clear, located error: the expected outcome for broken input.
    }
    return 0;
}
