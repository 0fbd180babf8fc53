// Output of a 1920x1080 render (docs/performance.md "Output"): the display transform, the PNG
// encoder at every zlib level, EXR at every zip level and other codecs, 16-bit TIFF at deflate
// levels 1-6, and write_image end to end for each format. The film is whitted1980.json rendered once at 1920x1080 (centre sampling). Bytes are
// reported as counters.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <type_traits>
#include <vector>

#include <unistd.h>

#include <Imath/half.h>

#include "importers/scene_loader.h"
#include "core/image_files.h"
#include "integrator/render.h"
#include "output/image_output.h"
#include "output/png_encoder.h"

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
    // Arguments: bits, and whether a new transform is made per image (its code table built
    // again, as in a run that writes one file) or one transform serves every image.
    const int bits = int(state.range(0));
    const bool fresh = state.range(1) != 0;
    const DisplayTransform kept{ColorSettings{}};
    std::vector<uint8_t> out(film().beauty.size() * 3 * size_t(bits / 8));
    for (auto _ : state) {
        if (fresh) display_codes(film().beauty, DisplayTransform(ColorSettings{}), bits, out);
        else display_codes(film().beauty, kept, bits, out);
    }
}
BENCHMARK(BM_DisplayCodes)->ArgsProduct({{8, 16}, {0, 1}})->ArgNames({"bits", "fresh"})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CodeTableBuild(benchmark::State& state) {
    // The table alone, per bit depth: made once per transform and bit depth.
    for (auto _ : state) benchmark::DoNotOptimize(DisplayTransform(ColorSettings{}).code_table(int(state.range(0))));
}
BENCHMARK(BM_CodeTableBuild)->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EncodePng(benchmark::State& state) {
    size_t bytes = 0;
    for (auto _ : state) bytes = encode_png(codes(), film().width(), film().height(), 8, {}, PngOptions{int(state.range(0)), 0}).size();
    state.counters["bytes"] = double(bytes);
}
BENCHMARK(BM_EncodePng)->DenseRange(0, 9)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The film's RGB as one writer takes it: every channel of type `type`, with `compression`.
ImageDesc rgb_desc(const char* format, PixelType type, const std::string& compression) {
    ImageDesc desc;
    desc.format_name = format;
    desc.width = film().width();
    desc.height = film().height();
    desc.channel_names = {"R", "G", "B"};
    desc.channel_types.assign(3, type);
    desc.attributes = {{"compression", compression}};
    return desc;
}

/// The beauty as T (half, as write_image writes it, or float: --exr-float) with the given compression.
template <typename T>
void write_exr_beauty(benchmark::State& state, const std::string& compression) {
    std::vector<T> rgb;
    rgb.reserve(film().beauty.size() * 3);
    for (const Color& c : film().beauty)
        for (float v : {c.x, c.y, c.z}) rgb.emplace_back(v);
    const PixelType type = std::is_same_v<T, float> ? PixelType::Float : PixelType::Half;
    const ImageDesc desc = rgb_desc("openexr", type, compression);
    const fs::path file = scratch(".exr");
    for (auto _ : state) write_image_file(file.string(), desc, rgb.data());
    state.counters["bytes"] = double(fs::file_size(file));
    fs::remove(file);
}
void write_exr_half(benchmark::State& state, const std::string& compression) {
    write_exr_beauty<Imath::half>(state, compression);
}
void write_exr_float(benchmark::State& state, const std::string& compression) {
    write_exr_beauty<float>(state, compression);
}
void BM_WriteExrZipLevel(benchmark::State& state) { write_exr_half(state, "zip:" + std::to_string(state.range(0))); }
BENCHMARK(BM_WriteExrZipLevel)->DenseRange(1, 9)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_exr_half, none, std::string("none"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_exr_half, rle, std::string("rle"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_exr_half, zips_1, std::string("zips:1"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_exr_half, piz, std::string("piz"))->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_CAPTURE(write_exr_float, zip_1, std::string("zip:1"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_exr_float, none, std::string("none"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_exr_float, rle, std::string("rle"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_exr_float, zips_1, std::string("zips:1"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_exr_float, piz, std::string("piz"))->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WriteTiff16Level(benchmark::State& state) {
    // 16-bit display codes as write_image makes them for TIFF, deflate level N.
    std::vector<uint8_t> codes16(film().beauty.size() * 6);
    display_codes(film().beauty, DisplayTransform(ColorSettings{}), 16, codes16);
    const ImageDesc desc = rgb_desc("tiff", PixelType::UInt16, "zip:" + std::to_string(state.range(0)));
    const fs::path file = scratch(".tif");
    for (auto _ : state) write_image_file(file.string(), desc, codes16.data());
    state.counters["bytes"] = double(fs::file_size(file));
    fs::remove(file);
}
BENCHMARK(BM_WriteTiff16Level)->DenseRange(1, 9)->Unit(benchmark::kMillisecond)->UseRealTime();

void write_format(benchmark::State& state, const std::string& ext, bool half, const std::string& tiff = "zip") {
    OutputSettings settings;
    settings.exr_half = half;
    settings.tiff_compression = tiff;
    if (ext == ".tif8") settings.bits = 8;
    const fs::path file = scratch(ext == ".tif8" ? ".tif" : ext);
    for (auto _ : state) write_image(film(), file.string(), settings);
    state.counters["bytes"] = double(fs::file_size(file));
    fs::remove(file);
}
BENCHMARK_CAPTURE(write_format, png, std::string(".png"), true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_format, exr_half, std::string(".exr"), true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_format, exr_float, std::string(".exr"), false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_format, jpeg, std::string(".jpg"), true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_format, tiff16, std::string(".tif"), true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_format, tiff8, std::string(".tif8"), true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_format, tiff16_none, std::string(".tif"), true, std::string("none"))
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(write_format, tiff8_none, std::string(".tif8"), true, std::string("none"))
    ->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
