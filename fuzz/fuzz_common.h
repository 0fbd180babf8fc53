// Shared by the libFuzzer harnesses (docs/fuzzing.md). A harness passes when every input either
// imports or throws whitted::Error: any other exception escapes to libFuzzer and is a finding,
// as are crashes, sanitizer reports, timeouts and allocations above -malloc_limit_mb.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "importers/scene_loader.h"
#include "importers/scene_report.h"
#include "core/error.h"
#include "core/log.h"

namespace whitted::fuzz {

/// Memory ceiling given to the importer: well under libFuzzer's default 2 GiB RSS limit, so an
/// over-large input must end in the importer's own error, not in an out-of-memory report.
constexpr size_t kMaxMemory = size_t(256) << 20;

/// A folder that does not exist: relative URIs resolve into it and find nothing, so a harness
/// never reads the file system (and ../ or absolute URIs are refused by the URI policy).
inline const std::string kFuzzFolder = "/nonexistent-whitted-fuzz";

/// Imports `bytes` as the file `name` (its extension picks .gltf or .glb) and, on success,
/// describes the scene as `whitted info` does.
inline void import_bytes(const uint8_t* data, size_t size, const std::string& name) {
    static const bool quiet = (set_log_level(LogLevel::Off), true);
    (void)quiet;
    ImportOptions options;
    options.max_memory = kMaxMemory;
    try {
        const Scene scene = import_gltf_memory(std::span<const uint8_t>(data, size), kFuzzFolder + "/" + name, options);
        (void)describe_scene(scene);
    } catch (const Error&) {
        // A clear, located error: the expected outcome for broken input.
    }
}

}  // namespace whitted::fuzz
