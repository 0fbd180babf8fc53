// Output of a 1920x1080 render (docs/performance.md "Output"): the display transform, the PNG
// encoder at every zlib level, EXR at every zip level, and write_image end to end for each
// format. The film is whitted1980.json rendered once at 1920x1080 (centre sampling). Bytes are
// reported as counters; the first JPEG/TIFF write loads the OIIO module outside the timing.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

#include <Imath/half.h>

#include "importers/scene_loader.h"
#include "renderer/core/image_files.h"
#include "renderer/integrator/render.h"
#include "renderer/output/image_output.h"
#include "renderer/output/png_encoder.h"

namespace {

using namespace whitted;
namespace fs = std::filesystem;

const Film& film() {
    static const Film f = [] {
        const Scene scene = load_scene(std::string(WHITTED_ASSETS_DIR) + "/scenes/whitted1980.json");
        RenderSettings rs;
        apply_scene_settings(scene.settings, rs);
        rs.width = 1920;
        rs.height = 1080;
        rs.aa = AaSettings{};  // centre
        return Renderer(scene, rs).render();
    }();
    return f;
}

const std::vector<uint8_t>& codes() {
    static const std::vector<uint8_t> c = [] {
        std::vector<uint8_t> out(film().beauty.size() * 3);
        display_codes(film().beauty, DisplayTransform(ColorSettings{}), 8, out);
        return out;
    }();
    return c;
}

fs::path scratch(const std::string& ext) {
    return fs::temp_directory_path() / ("whitted_bench_output_" + std::to_string(::getpid()) + ext);
}

void BM_DisplayCodes(benchmark::State& state) {
    const DisplayTransform transform{ColorSettings{}};
    std::vector<uint8_t> out(film().beauty.size() * 3);
    for (auto _ : state) display_codes(film().beauty, transform, 8, out);
}
BENCHMARK(BM_DisplayCodes)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EncodePng(benchmark::State& state) {
    size_t bytes = 0;
    for (auto _ : state) bytes = encode_png(codes(), film().width(), film().height(), 8, {}, PngOptions{int(state.range(0)), 0}).size();
    state.counters["bytes"] = double(bytes);
}
BENCHMARK(BM_EncodePng)->DenseRange(0, 9)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WriteExrZipLevel(benchmark::State& state) {
    // The beauty as half, as write_image writes it, with compression "zip:<level>".
    std::vector<Imath::half> half;
    half.reserve(film().beauty.size() * 3);
    for (const Color& c : film().beauty)
        for (float v : {c.x, c.y, c.z}) half.emplace_back(v);
    ImageDesc desc;
    desc.format_name = "openexr";
    desc.width = film().width();
    desc.height = film().height();
    desc.channel_names = {"R", "G", "B"};
    desc.channel_types.assign(3, PixelType::Half);
    desc.attributes = {{"compression", "zip:" + std::to_string(state.range(0))}};
    const fs::path file = scratch(".exr");
    for (auto _ : state) write_image_file(file.string(), desc, half.data());
    state.counters["bytes"] = double(fs::file_size(file));
    fs::remove(file);
}
BENCHMARK(BM_WriteExrZipLevel)->DenseRange(1, 9)->Unit(benchmark::kMillisecond)->UseRealTime();

void write_format(benchmark::State& state, const std::string& ext, bool half) {
    OutputSettings settings;
    settings.exr_half = half;
    const fs::path file = scratch(ext);
    write_image(film(), file.string(), settings);  // the first JPEG/TIFF loads the OIIO module
    for (auto _ : state) write_image(film(), file.string(), settings);
    state.counters["bytes"] = double(fs::file_size(file));
    fs::remove(file);
}
BENCHMARK_CAPTURE(write_format, png, std::string(".png"), true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_format, exr_half, std::string(".exr"), true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_format, exr_float, std::string(".exr"), false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_format, jpeg, std::string(".jpg"), true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_format, tiff16, std::string(".tif"), true)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
