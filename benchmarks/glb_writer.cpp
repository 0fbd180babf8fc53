// The GLB container of the generated benchmark scenes (glb_writer.h).
#include "benchmarks/glb_writer.h"

#include <fstream>

#include "core/error.h"

namespace whitted::app {

namespace {

void put_u32(std::string& s, uint32_t v) {
    for (int b = 0; b < 4; ++b) s.push_back(char((v >> (8 * b)) & 0xFF));
}

}  // namespace

std::string join(const std::vector<std::string>& items, const char* separator) {
    std::string out;
    for (size_t i = 0; i < items.size(); ++i) out += (i ? separator : "") + items[i];
    return out;
}

size_t write_glb(const std::filesystem::path& path, const std::string& json, const std::vector<uint8_t>& bin,
                 const char* what) {
    std::string json_chunk = json;
    json_chunk.resize((json_chunk.size() + 3) & ~size_t(3), ' ');
    const size_t total = 12 + 8 + json_chunk.size() + 8 + bin.size();
    if (total > 0xFFFFFFFFu) throw Error(fmt::format("{}: {} bytes do not fit a GLB", what, total));
    std::string head = "glTF";
    put_u32(head, 2);
    put_u32(head, uint32_t(total));
    put_u32(head, uint32_t(json_chunk.size()));
    head += "JSON";
    std::string bin_head;
    put_u32(bin_head, uint32_t(bin.size()));
    bin_head += std::string("BIN\0", 4);
    std::ofstream f(path, std::ios::binary);
    f.write(head.data(), std::streamsize(head.size()));
    f.write(json_chunk.data(), std::streamsize(json_chunk.size()));
    f.write(bin_head.data(), std::streamsize(bin_head.size()));
    f.write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size()));
    if (!f) throw Error(fmt::format("{}: cannot write {}", what, path.string()));
    return total;
}

}  // namespace whitted::app
