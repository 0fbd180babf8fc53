// libFuzzer harness: the glTF importer on .glb bytes. A structure-aware mutator keeps the GLB
// container valid most of the time (it mutates the JSON or the BIN chunk and rewrites the
// lengths), so the fuzzer gets past the container checks into the parser and the validation;
// one mutation in eight is applied to the raw bytes to keep exercising the container checks.
#include <cstring>
#include <random>
#include <vector>

#include "fuzz/fuzz_common.h"

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t max_size);

namespace {

uint32_t load_u32(const uint8_t* p) {
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

void append_u32(std::vector<uint8_t>& out, uint32_t v) {
    uint8_t b[4];
    std::memcpy(b, &v, 4);
    out.insert(out.end(), b, b + 4);
}

/// Splits a well-formed GLB into its JSON and BIN chunk payloads; false when it is not one.
bool split_glb(const uint8_t* data, size_t size, std::vector<uint8_t>& json, std::vector<uint8_t>& bin, bool& has_bin) {
    if (size < 20 || std::memcmp(data, "glTF", 4) != 0) return false;
    const uint64_t json_length = load_u32(data + 12);
    if (load_u32(data + 16) != 0x4E4F534Au || 20 + json_length > size) return false;
    json.assign(data + 20, data + 20 + json_length);
    const uint64_t bin_start = 20 + json_length;
    has_bin = bin_start + 8 <= size;
    if (has_bin) {
        const uint64_t bin_length = std::min<uint64_t>(load_u32(data + bin_start), size - bin_start - 8);
        bin.assign(data + bin_start + 8, data + bin_start + 8 + bin_length);
    }
    return true;
}

/// Assembles a GLB (version 2) with consistent lengths; JSON padded with spaces, BIN with zeros.
std::vector<uint8_t> join_glb(std::vector<uint8_t> json, std::vector<uint8_t> bin, bool has_bin) {
    while (json.size() % 4 != 0) json.push_back(' ');
    while (bin.size() % 4 != 0) bin.push_back(0);
    std::vector<uint8_t> out;
    out.insert(out.end(), {'g', 'l', 'T', 'F'});
    append_u32(out, 2);
    append_u32(out, uint32_t(12 + 8 + json.size() + (has_bin ? 8 + bin.size() : 0)));
    append_u32(out, uint32_t(json.size()));
    append_u32(out, 0x4E4F534Au);  // "JSON"
    out.insert(out.end(), json.begin(), json.end());
    if (has_bin) {
        append_u32(out, uint32_t(bin.size()));
        append_u32(out, 0x004E4942u);  // "BIN\0"
        out.insert(out.end(), bin.begin(), bin.end());
    }
    return out;
}

}  // namespace

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t max_size, unsigned int seed) {
    std::minstd_rand rng(seed);
    std::vector<uint8_t> json, bin;
    bool has_bin = false;
    if (rng() % 8 == 0 || !split_glb(data, size, json, bin, has_bin)) return LLVMFuzzerMutate(data, size, max_size);

    // Mutate one chunk in place (with room to grow), then rebuild the container.
    const bool mutate_json = !has_bin || bin.empty() || rng() % 3 != 0;
    std::vector<uint8_t>& chunk = mutate_json ? json : bin;
    const size_t overhead = 20 + (has_bin ? 8 : 0) + 6;  // headers and padding
    if (max_size <= overhead + json.size() + bin.size() - chunk.size()) return LLVMFuzzerMutate(data, size, max_size);
    const size_t chunk_max = max_size - overhead - (json.size() + bin.size() - chunk.size());
    const size_t old_size = chunk.size();
    chunk.resize(std::max(chunk_max, old_size));
    chunk.resize(LLVMFuzzerMutate(chunk.data(), std::min(old_size, chunk_max), chunk_max));
    const std::vector<uint8_t> out = join_glb(std::move(json), std::move(bin), has_bin);
    if (out.size() > max_size) return LLVMFuzzerMutate(data, size, max_size);
    std::memcpy(data, out.data(), out.size());
    return out.size();
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    whitted::fuzz::import_bytes(data, size, "input.glb");
    return 0;
}
