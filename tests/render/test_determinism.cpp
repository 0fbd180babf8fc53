// The image must be bit-identical for any thread count and any tile size (including tile sizes
// that do not divide the image), also with glass, mirrors and transparent shadows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <optional>
#include <random>
#include <vector>

#include "core/fp_mode.h"
#include "integrator/render.h"
#include "scene/scene_builder.h"

namespace whitted {
namespace {

/// Floor, a mirror box, a refracting glass box, a thin tinted panel, two lights.
Scene glass_and_shadows_scene() {
    Scene s;
    WhittedCoeffs floor;
    floor.kd = floor.ka = Color(0.6f, 0.55f, 0.5f);
    floor.ks = Color(0.1f);
    floor.n = 20.f;
    add_mesh(s, make_quad({-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}, add_classic_material(s, floor)));
    WhittedCoeffs mirror;
    mirror.kr = Color(0.8f);
    mirror.kd = mirror.ka = Color(0.1f);
    add_mesh(s, make_box({-2.5f, -0.5f, 0}, {-1.5f, 0.5f, 1.5f}, add_classic_material(s, mirror)));
    WhittedCoeffs glass;
    glass.kt = Color(0.9f);
    glass.kr = Color(0.05f);
    glass.ior = 1.5f;
    glass.thin = false;
    add_mesh(s, make_box({-0.5f, -0.5f, 0}, {0.5f, 0.5f, 1.2f}, add_classic_material(s, glass)));
    WhittedCoeffs tint;
    tint.kt = Color(0.9f, 0.3f, 0.2f);
    tint.kd = tint.ka = Color(0.05f);
    add_mesh(s, make_quad({1.5f, -0.5f, 0.2f}, {2.5f, -0.5f, 0.2f}, {2.5f, 0.5f, 1.2f}, {1.5f, 0.5f, 1.2f},
                          add_classic_material(s, tint)));
    s.lights.push_back(point_light({2, -3, 5}, 30.f, {1.f, 0.9f, 0.8f}));
    s.lights.push_back(point_light({-3, -2, 4}, 15.f, {0.6f, 0.7f, 1.f}));
    s.cameras.push_back(make_camera(CameraType::Perspective, {0, -7, 3.5}, {0, 7, -3}, {0, 0, 1}, 0.7));
    return s;
}

/// The tests' settings: 97 x 61 (odd on purpose: no tile size below divides it), with `aa`.
RenderSettings settings(int threads, int tile, const AaSettings& aa, bool aovs = true) {
    RenderSettings rs;
    rs.width = 97;
    rs.height = 61;
    rs.threads = threads;
    rs.tile_size = tile;
    if (aovs) rs.aovs = AovSet{true, true, true, true, true, true};
    rs.aa = aa;
    return rs;
}

Film render(const Scene& s, int threads, int tile, const AaSettings& aa = {}, RenderStats* stats = nullptr) {
    Renderer r(s, settings(threads, tile, aa));
    return r.render(stats);
}

bool bit_identical(const Film& a, const Film& b) {
    return a.beauty.size() == b.beauty.size() &&
           std::memcmp(a.beauty.data(), b.beauty.data(), a.beauty.size() * sizeof(Color)) == 0 &&
           std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)) == 0 &&
           std::memcmp(a.normal.data(), b.normal.data(), a.normal.size() * sizeof(Vec3f)) == 0 &&
           a.prim_id == b.prim_id && a.inst_id == b.inst_id && a.aa_samples == b.aa_samples;
}

/// Every anti-aliasing mode, with settings that exercise its sharing across tiles.
std::vector<AaSettings> all_aa_modes() {
    std::vector<AaSettings> modes;
    AaSettings a;
    a.mode = AaMode::Center;
    modes.push_back(a);
    a.mode = AaMode::Corners;
    modes.push_back(a);
    a.mode = AaMode::Adaptive;  // the CLI default: threshold 0.1, depth 3
    modes.push_back(a);
    a.threshold = -1.f;  // always split: every edge point is shared
    a.depth = 3;
    modes.push_back(a);
    a = AaSettings{};
    a.mode = AaMode::Stratified;
    a.spp = 4;
    modes.push_back(a);
    a.filter = PixelFilter::Tent;
    modes.push_back(a);
    return modes;
}

TEST(Determinism, ThreadCountAndTileSizeDoNotChangeTheImage) {
    const Scene s = glass_and_shadows_scene();
    const Film reference = render(s, 1, 32);
    // The scene really has glass, reflections and tinted shadows: the image is not trivial.
    RenderSettings rs;
    rs.width = 97;
    rs.height = 61;
    RenderStats stats;
    Renderer(s, rs).render(&stats);
    EXPECT_GT(stats.rays.refraction, 100u);
    EXPECT_GT(stats.rays.reflection, 100u);
    EXPECT_GT(stats.rays.shadow, 1000u);

    for (auto [threads, tile] : {std::pair{8, 32}, std::pair{2, 7}, std::pair{8, 13}, std::pair{3, 1}, std::pair{8, 200}})
        EXPECT_TRUE(bit_identical(reference, render(s, threads, tile))) << threads << " threads, tile " << tile;
}

TEST(Determinism, EveryAaModeIsIndependentOfThreadsAndTiles) {
    const Scene s = glass_and_shadows_scene();
    for (const AaSettings& aa : all_aa_modes()) {
        RenderStats ref_stats;
        const Film reference = render(s, 1, 32, aa, &ref_stats);
        for (auto [threads, tile] : {std::pair{2, 7}, std::pair{3, 1}, std::pair{8, 200}}) {
            RenderStats stats;
            EXPECT_TRUE(bit_identical(reference, render(s, threads, tile, aa, &stats)))
                << aa_mode_name(aa.mode) << " t=" << aa.threshold << ": " << threads << " threads, tile " << tile;
            // Shared samples are traced once whatever the tiling: the counts match exactly.
            EXPECT_EQ(stats.rays.camera, ref_stats.rays.camera) << aa_mode_name(aa.mode) << " tile " << tile;
            EXPECT_EQ(stats.rays.total(), ref_stats.rays.total()) << aa_mode_name(aa.mode) << " tile " << tile;
        }
    }
}

// Renderer::render_tiles, the one frame path (render(), distributed, resumed and tile-job renders):
// the tiles in any order, pasted together, are render()'s image, every buffer bit for bit, in every
// anti-aliasing mode, and the samples neighbouring tiles share are traced once (the same rays).
TEST(Determinism, TilesRenderedAloneInAnyOrderMakeTheSameImage) {
    const Scene s = glass_and_shadows_scene();
    for (const AaSettings& aa : all_aa_modes()) {
        RenderStats ref_stats;
        const Film reference = render(s, 1, 32, aa, &ref_stats);
        for (auto [threads, tile] : {std::pair{2, 7}, std::pair{3, 16}, std::pair{1, 200}}) {
            const RenderSettings rs = settings(threads, tile, aa);
            const Renderer r(s, rs);
            const size_t n = r.tiles().size();
            std::vector<size_t> order(n);
            std::iota(order.begin(), order.end(), size_t(0));
            std::shuffle(order.begin(), order.end(), std::mt19937(uint32_t(n)));
            Film assembled(97, 61, PixelWindow{0, 0, 97, 61}, rs.aovs);
            size_t handed = 0, finished = 0;
            RenderStats stats;
            r.render_tiles([&]() -> std::optional<size_t> { return handed < n ? std::optional(order[handed++]) : std::nullopt; },
                           [&](size_t, Film&& f) { assembled.paste(f); ++finished; }, &stats);
            EXPECT_EQ(finished, n);
            EXPECT_EQ(stats.pixels, 97u * 61u);
            EXPECT_EQ(stats.rays.camera, ref_stats.rays.camera) << aa_mode_name(aa.mode) << " tile " << tile;
            EXPECT_EQ(stats.rays.total(), ref_stats.rays.total()) << aa_mode_name(aa.mode) << " tile " << tile;
            EXPECT_TRUE(bit_identical(reference, assembled))
                << aa_mode_name(aa.mode) << " t=" << aa.threshold << ": " << threads << " threads, tile " << tile;
        }
    }
}

// A process that renders only some of the tiles (an MPI rank, a resumed render) traces their
// samples alone: its tiles are render()'s pixels, and the corners along its own borders are traced
// again by whoever renders the neighbours: --aa corners over the even tiles traces exactly the
// corners of those tiles, each once.
TEST(Determinism, SomeTilesTraceOnlyTheirOwnCorners) {
    const Scene s = glass_and_shadows_scene();
    AaSettings aa;
    aa.mode = AaMode::Corners;
    const Film reference = render(s, 1, 32, aa);
    const RenderSettings rs = settings(3, 10, aa, false);
    const Renderer r(s, rs);
    const std::vector<TileRect> tiles = r.tiles();
    std::vector<size_t> mine;
    for (size_t i = 0; i < tiles.size(); i += 2) mine.push_back(i);
    std::vector<uint8_t> corner(98u * 62u, 0);
    for (const size_t i : mine)
        for (int y = tiles[i].y0; y <= tiles[i].y1; ++y)
            for (int x = tiles[i].x0; x <= tiles[i].x1; ++x) corner[size_t(y) * 98u + size_t(x)] = 1;
    size_t handed = 0;
    RenderStats stats;
    Film assembled(97, 61, PixelWindow{0, 0, 97, 61}, rs.aovs);
    r.render_tiles([&]() -> std::optional<size_t> { return handed < mine.size() ? std::optional(mine[handed++]) : std::nullopt; },
                   [&](size_t, Film&& f) {
                       for (int y = f.window.y0; y < f.window.y1; ++y)
                           for (int x = f.window.x0; x < f.window.x1; ++x)
                               EXPECT_EQ(std::memcmp(&f.beauty[f.index(x, y)], &reference.beauty[reference.index(x, y)],
                                                     sizeof(Color)), 0) << x << "," << y;
                   },
                   &stats);
    EXPECT_EQ(stats.rays.camera, uint64_t(std::count(corner.begin(), corner.end(), uint8_t(1))));
}

TEST(Determinism, EveryAaModeCropsToTheSamePixels) {
    const Scene s = glass_and_shadows_scene();
    for (const AaSettings& aa : all_aa_modes()) {
        const Film full = render(s, 2, 16, aa);
        RenderSettings rs = settings(2, 9, aa, false);
        rs.crop = PixelWindow{10, 5, 60, 40};
        const Film crop = Renderer(s, rs).render();
        for (int y = 5; y < 40; ++y)
            for (int x = 10; x < 60; ++x)
                ASSERT_EQ(crop.beauty[crop.index(x, y)], full.beauty[full.index(x, y)]) << aa_mode_name(aa.mode);
    }
}

TEST(Determinism, CropRendersTheSamePixelsAsTheFullImage) {
    const Scene s = glass_and_shadows_scene();
    const Film full = render(s, 2, 16);
    RenderSettings rs;
    rs.width = 97;
    rs.height = 61;
    rs.threads = 2;
    rs.crop = PixelWindow{10, 5, 60, 40};
    Film crop = Renderer(s, rs).render();
    ASSERT_EQ(crop.width(), 50);
    ASSERT_EQ(crop.height(), 35);
    for (int y = 5; y < 40; ++y)
        for (int x = 10; x < 60; ++x) ASSERT_EQ(crop.beauty[crop.index(x, y)], full.beauty[full.index(x, y)]);
}

// The renderer traces with flush-to-zero / denormals-are-zero (src/core/fp_mode.h) but is a
// library: the calling thread's floating-point mode must be the same after constructing a Renderer
// and after render() (with 1 and 2 threads; the caller's thread works in the arena too), and
// denormal arithmetic must work again afterwards. Setting FTZ/DAZ and leaving it set fails this.
TEST(Determinism, RendererRestoresTheCallersFloatingPointMode) {
    const Scene s = glass_and_shadows_scene();
    // The control bits (rounding, exception masks, FTZ, DAZ), not the sticky exception flags.
    auto mode = [] { return _mm_getcsr() & ~0x3Fu; };
    const unsigned before = mode();
    ASSERT_EQ(before & (ScopedFlushDenormals::kFtz | ScopedFlushDenormals::kDaz), 0u) << "test runner set FTZ/DAZ";
    for (int threads : {1, 2}) {
        RenderSettings rs;
        rs.width = 33;
        rs.height = 21;
        rs.threads = threads;
        Renderer r(s, rs);
        EXPECT_EQ(mode(), before) << "after the constructor, threads " << threads;
        const Film film = r.render();
        EXPECT_EQ(mode(), before) << "after render(), threads " << threads;
    }
    volatile float tiny = 1e-38f;  // a normal float; /100 is denormal unless flushed
    EXPECT_GT(tiny / 100.f, 0.f);
    {
        const ScopedFlushDenormals ftz;
        EXPECT_EQ(_mm_getcsr() & ScopedFlushDenormals::kFtz, ScopedFlushDenormals::kFtz);
        EXPECT_EQ(tiny / 100.f, 0.f);  // flushed inside the scope
    }
    EXPECT_EQ(mode(), before);
}

}  // namespace
}  // namespace whitted
