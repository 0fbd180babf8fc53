// Anti-aliasing modes: exact primary-ray counts (shared corners, adaptive recursion), the adaptive
// estimate against an independent uniform subdivision and an independent depth-first recursion (pixels
// bit for bit, ray counts), stratified sampling, AOVs.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "accel/factory/create_accelerator.h"
#include "core/error.h"
#include "integrator/render.h"
#include "scene/scene_builder.h"

namespace whitted {
namespace {

/// Orthographic camera looking down -z whose image x equals world x + width / 2 (square pixels of
/// one world unit), and a flat half-plane x < edge_x (image coordinates) of constant radiance 1
/// (ambient only) over a black background: a single vertical edge.
Scene vertical_edge_scene(int size, double edge_x) {
    Scene s;
    WhittedCoeffs white;
    white.ka = Color(1.f);
    const float e = float(edge_x - size / 2.0);
    add_mesh(s, make_quad({-1000, -1000, 0}, {e, -1000, 0}, {e, 1000, 0}, {-1000, 1000, 0}, add_classic_material(s, white)));
    s.cameras.push_back(make_camera(CameraType::Orthographic, {0, 0, 5}, {0, 0, -1}, {0, 1, 0}, size / 2.0));
    return s;
}

/// A plane filling the view with constant radiance: every sample has the same colour.
Scene flat_scene() { return vertical_edge_scene(16, 1e6); }

/// Glass, mirror and shadows seen in perspective (the determinism test's kind of scene, smaller).
Scene busy_scene() {
    Scene s;
    WhittedCoeffs floor;
    floor.kd = floor.ka = Color(0.6f, 0.55f, 0.5f);
    const uint32_t floor_material = add_classic_material(s, floor);
    // Whitted's checkerboard in world space: its filtered value depends on each sample's footprint.
    Texture checker;
    checker.name = "checker";
    checker.kind = TextureKind::Checker;
    checker.checker.size = 0.7f;
    checker.checker.world_space = true;
    s.textures.push_back(checker);
    s.materials[floor_material].classic_color_texture.texture = 0;
    add_mesh(s, make_quad({-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}, floor_material));
    WhittedCoeffs mirror;
    mirror.kr = Color(0.8f);
    mirror.kd = mirror.ka = Color(0.1f);
    add_mesh(s, make_box({-2.f, -0.5f, 0}, {-1.f, 0.5f, 1.5f}, add_classic_material(s, mirror)));
    WhittedCoeffs glass;
    glass.kt = Color(0.9f);
    glass.ior = 1.5f;
    glass.thin = false;
    add_mesh(s, make_box({0.f, -0.5f, 0}, {1.f, 0.5f, 1.2f}, add_classic_material(s, glass)));
    s.lights.push_back(point_light({2, -3, 5}, 30.f));
    s.cameras.push_back(make_camera(CameraType::Perspective, {0, -7, 3.5}, {0, 7, -3}, {0, 0, 1}, 0.7));
    return s;
}

RenderSettings settings(int w, int h, AaMode mode, int tile = 8, int threads = 2) {
    RenderSettings rs;
    rs.width = w;
    rs.height = h;
    rs.tile_size = tile;
    rs.threads = threads;
    rs.integrator.ambient = Color(1.f);
    rs.aa.mode = mode;
    return rs;
}

TEST(AaSampling, CornersTraceEachLatticePointOnce) {
    const Scene s = busy_scene();
    for (auto [w, h, tile] : {std::tuple{37, 23, 8}, std::tuple{37, 23, 1}, std::tuple{16, 16, 16}, std::tuple{5, 3, 200}}) {
        RenderStats stats;
        Renderer(s, settings(w, h, AaMode::Corners, tile)).render(&stats);
        EXPECT_EQ(stats.rays.camera, uint64_t(w + 1) * uint64_t(h + 1)) << w << "x" << h << " tile " << tile;
        EXPECT_EQ(stats.rays.aov_probe, 0u);
    }
    // A crop traces its own lattice: (w+1)(h+1) of the crop.
    RenderSettings rs = settings(37, 23, AaMode::Corners);
    rs.crop = PixelWindow{3, 4, 20, 11};
    RenderStats stats;
    Renderer(s, rs).render(&stats);
    EXPECT_EQ(stats.rays.camera, uint64_t(18 * 8));
}

TEST(AaSampling, CornersPixelIsTheMeanOfItsCorners) {
    // On the vertical edge at x = 10.3 the pixel [10, 11) has two white corners (x = 10) and two
    // black ones (x = 11): 0.5. Pixels left of it are 1, right of it 0.
    const Scene s = vertical_edge_scene(32, 10.3);
    Film film = Renderer(s, settings(32, 32, AaMode::Corners)).render();
    for (int y : {0, 13, 31}) {
        EXPECT_FLOAT_EQ(film.beauty[film.index(9, y)].x, 1.f);
        EXPECT_FLOAT_EQ(film.beauty[film.index(10, y)].x, 0.5f);
        EXPECT_FLOAT_EQ(film.beauty[film.index(11, y)].x, 0.f);
    }
}

TEST(AaSampling, AdaptiveOnAFlatImageTracesOnlyTheCorners) {
    const Scene s = flat_scene();
    for (int depth : {1, 3, 6}) {
        RenderSettings rs = settings(16, 16, AaMode::Adaptive);
        rs.aa.depth = depth;
        rs.aa.threshold = 0.f;  // any difference splits: there is none
        RenderStats stats;
        Film film = Renderer(s, rs).render(&stats);
        EXPECT_EQ(stats.rays.camera, 17u * 17u) << "depth " << depth;
        EXPECT_EQ(stats.pixels_subdivided, 0u);
        for (const Color& c : film.beauty) ASSERT_EQ(c, Color(1.f));
    }
}

/// The recursion's point set for one vertical edge at image x = e (not a dyadic fraction), built
/// independently: a square splits exactly when the edge passes strictly between its left and
/// right sides; every corner of every visited square is a distinct traced point.
uint64_t predicted_edge_rays(int w, int h, double e, int depth) {
    const int n = 1 << depth;
    std::set<std::pair<int64_t, int64_t>> points;  // in units of 1/n pixel
    auto visit = [&](auto&& self, int64_t x0, int64_t y0, int64_t size, int level) -> void {
        for (auto [dx, dy] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}})
            points.insert({x0 + dx * size, y0 + dy * size});
        const bool straddles = double(x0) / n < e && e < double(x0 + size) / n;
        if (level < depth && straddles) {
            const int64_t half = size / 2;
            for (auto [dx, dy] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}})
                self(self, x0 + dx * half, y0 + dy * half, half, level + 1);
        }
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) visit(visit, int64_t(x) * n, int64_t(y) * n, n, 0);
    return points.size();
}

TEST(AaSampling, AdaptiveOnAVerticalEdgeTracesWhatTheRecursionNeeds) {
    for (double e : {10.3, 7.71, 12.5 + 1.0 / 3.0})
        for (int depth : {1, 2, 3, 5}) {
            const Scene s = vertical_edge_scene(24, e);
            for (auto [tile, threads] : {std::pair{8, 2}, std::pair{1, 3}, std::pair{5, 1}}) {
                RenderSettings rs = settings(24, 24, AaMode::Adaptive, tile, threads);
                rs.aa.depth = depth;
                rs.aa.threshold = 0.1f;
                RenderStats stats;
                Film film = Renderer(s, rs).render(&stats);
                EXPECT_EQ(stats.rays.camera, predicted_edge_rays(24, 24, e, depth))
                    << "edge " << e << " depth " << depth << " tile " << tile;
                EXPECT_EQ(stats.pixels_subdivided, 24u) << "one column of pixels holds the edge";
                // The edge pixel converges to its coverage: within half a leaf of the exact area.
                const float coverage = float(e - std::floor(e));
                EXPECT_NEAR(film.beauty[film.index(int(e), 3)].x, coverage, 0.5f / float(1 << depth) + 1e-6f);
            }
        }
}

/// The test's own radiance at image position (x, y) of a w x h image: camera + integrator, one
/// ray at a time, no Renderer (the accelerator built as the Renderer builds it).
struct PerRayRadiance {
    PerRayRadiance(const Scene& s, const RenderSettings& rs, int w, int h)
        : view(s, rs.mapping), accel(create_accelerator("embree", s, view, AccelConfig{rs.robust, 0})),
          integrator(view, *accel, rs.integrator), camera(s.cameras[0], w, h) {}
    /// `spacing`: the sample's texture footprint in pixels (the ray cone's scale).
    Color operator()(double x, double y, float spacing = 1.f) const {
        RayCounters rc;
        const RayCone pixel = camera.pixel_cone();
        return integrator.trace(camera.generate(x, y), RayKind::Camera, 0, rc, nullptr,
                                RayCone{pixel.width * spacing, pixel.spread * spacing});
    }
    SceneView view;
    std::unique_ptr<Accelerator> accel;
    WhittedIntegrator integrator;
    CameraModel camera;
};

/// The texture footprint of point (X, Y) of a 1/n-pixel lattice (n a power of 2), as the test
/// derives it: the side of the largest sub-square of the pixel recursion (at most the pixel) that
/// has the point as a corner, in pixels.
float lattice_point_spacing(int64_t X, int64_t Y, int n) {
    int64_t g = n;
    while (X % g != 0 || Y % g != 0) g /= 2;
    return float(g) / float(n);
}

TEST(AaSampling, AdaptivePointSpacingIsTheSubSquareThatCreatedThePoint) {
    EXPECT_EQ(adaptive_point_spacing(0, 0, 3), 1.f);      // pixel corners
    EXPECT_EQ(adaptive_point_spacing(8, 0, 3), 1.f);
    EXPECT_EQ(adaptive_point_spacing(4, 0, 3), 0.5f);     // first split: edge midpoints and centre
    EXPECT_EQ(adaptive_point_spacing(4, 4, 3), 0.5f);
    EXPECT_EQ(adaptive_point_spacing(2, 4, 3), 0.25f);
    EXPECT_EQ(adaptive_point_spacing(8, 6, 3), 0.25f);
    EXPECT_EQ(adaptive_point_spacing(1, 0, 3), 0.125f);
    EXPECT_EQ(adaptive_point_spacing(7, 8, 3), 0.125f);
    EXPECT_EQ(adaptive_point_spacing(0, 0, 0), 1.f);
    for (int i = 0; i <= 32; ++i)
        for (int j = 0; j <= 32; ++j) EXPECT_EQ(adaptive_point_spacing(i, j, 5), lattice_point_spacing(i, j, 32));
}

TEST(AaSampling, AlwaysSplitEqualsAnIndependentUniformSubdivision) {
    const Scene s = busy_scene();
    const int w = 19, h = 13;
    RenderSettings base = settings(w, h, AaMode::Adaptive);
    base.integrator.ambient = Color(0.05f);
    const PerRayRadiance radiance(s, base, w, h);

    for (int depth : {1, 2}) {
        RenderSettings rs = base;
        rs.aa.depth = depth;
        rs.aa.threshold = -1.f;
        RenderStats stats;
        Film film = Renderer(s, rs).render(&stats);
        const int n = 1 << depth;
        // Every point of the (w n + 1) x (h n + 1) lattice is traced, once, whether the pixel edges
        // it lies on are inside a tile (handed to the next pixel), on a tile border (shared across
        // tiles) or on the window's border (not shared): one-pixel tiles, uneven tiles, one tile.
        EXPECT_EQ(stats.rays.camera, uint64_t(w * n + 1) * uint64_t(h * n + 1));
        EXPECT_EQ(stats.pixels_subdivided, uint64_t(w * h));
        for (int tile : {1, 5, 32}) {
            RenderSettings tiled = rs;
            tiled.tile_size = tile;
            RenderStats tiled_stats;
            const Film tiled_film = Renderer(s, tiled).render(&tiled_stats);
            EXPECT_EQ(tiled_stats.rays.camera, stats.rays.camera) << "tile " << tile << " depth " << depth;
            EXPECT_EQ(tiled_film.beauty, film.beauty) << "tile " << tile << " depth " << depth;
        }
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                Color sum(0.f);
                for (int j = 0; j < n; ++j)
                    for (int i = 0; i < n; ++i) {
                        const double x0 = x + double(i) / n, y0 = y + double(j) / n, x1 = x0 + 1.0 / n, y1 = y0 + 1.0 / n;
                        auto at = [&](int di, int dj, double px, double py) {
                            return radiance(px, py, lattice_point_spacing(int64_t(x) * n + i + di, int64_t(y) * n + j + dj, n));
                        };
                        sum += (at(0, 0, x0, y0) + at(1, 0, x1, y0) + at(0, 1, x0, y1) + at(1, 1, x1, y1)) * 0.25f;
                    }
                const Color want = sum * (1.f / float(n * n));
                const Color got = film.beauty[film.index(x, y)];
                for (int c = 0; c < 3; ++c)
                    ASSERT_NEAR(got[c], want[c], 1e-5f * std::max(1.f, std::abs(want[c])))
                        << "pixel " << x << "," << y << " depth " << depth;
            }
    }
}

TEST(AaSampling, AdaptiveEqualsAnIndependentDepthFirstRecursion) {
    // The renderer refines a pixel one level at a time and traces each level's new points in camera
    // batches; Whitted's recursion is depth first. With a real threshold on glass, mirrors and
    // shadows, the test's own depth-first recursion (camera + integrator, one ray at a time) must
    // give the same pixels bit for bit and visit as many distinct points as the renderer traces.
    const Scene s = busy_scene();
    const int w = 23, h = 17;
    RenderSettings base = settings(w, h, AaMode::Adaptive);
    base.integrator.ambient = Color(0.05f);
    const PerRayRadiance radiance(s, base, w, h);

    for (int depth : {1, 2, 3})
        for (float threshold : {0.2f, 0.05f}) {
            const int n = 1 << depth;
            std::set<std::pair<int64_t, int64_t>> points;  // in units of 1/n pixel
            uint64_t split_pixels = 0;
            // Area-weighted radiance of the square at (x0, y0) (units of 1/n pixel), Whitted's formula.
            auto visit = [&](auto&& self, int64_t x0, int64_t y0, int64_t size, int level) -> Color {
                Color c[4];
                int k = 0;
                for (auto [dx, dy] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}}) {
                    points.insert({x0 + dx * size, y0 + dy * size});
                    c[k++] = radiance(double(x0 + dx * size) / n, double(y0 + dy * size) / n,
                                      lattice_point_spacing(x0 + dx * size, y0 + dy * size, n));
                }
                if (level < depth && aa_contrast(c[0], c[1], c[2], c[3]) > threshold) {
                    if (level == 0) ++split_pixels;
                    const int64_t half = size / 2;
                    return self(self, x0, y0, half, level + 1) + self(self, x0 + half, y0, half, level + 1) +
                           self(self, x0, y0 + half, half, level + 1) + self(self, x0 + half, y0 + half, half, level + 1);
                }
                const float area = float(size) * float(size) / (float(n) * float(n));
                return (c[0] + c[1] + c[2] + c[3]) * (0.25f * area);
            };
            std::vector<Color> want(size_t(w) * size_t(h));
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) want[size_t(y * w + x)] = visit(visit, int64_t(x) * n, int64_t(y) * n, n, 0);
            ASSERT_GT(split_pixels, 0u);
            ASSERT_LT(split_pixels, uint64_t(w * h)) << "some pixels must stay unsplit";

            for (auto [tile, threads] : {std::pair{8, 2}, std::pair{1, 3}, std::pair{5, 1}, std::pair{32, 1}}) {
                RenderSettings rs = base;
                rs.aa.depth = depth;
                rs.aa.threshold = threshold;
                rs.tile_size = tile;
                rs.threads = threads;
                RenderStats stats;
                const Film film = Renderer(s, rs).render(&stats);
                EXPECT_EQ(stats.rays.camera, points.size()) << "depth " << depth << " threshold " << threshold << " tile " << tile;
                EXPECT_EQ(stats.pixels_subdivided, split_pixels);
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x)
                        ASSERT_EQ(film.beauty[film.index(x, y)], want[size_t(y * w + x)])
                            << "pixel " << x << "," << y << " depth " << depth << " threshold " << threshold << " tile " << tile;
            }
        }
}

TEST(AaSampling, StratifiedTracesSppRaysPerPixelAndIsSeededByPixel) {
    const Scene s = busy_scene();
    for (PixelFilter filter : {PixelFilter::Box, PixelFilter::Tent}) {
        RenderSettings rs = settings(21, 15, AaMode::Stratified);
        rs.aa.spp = 9;
        rs.aa.filter = filter;
        RenderStats stats;
        Film full = Renderer(s, rs).render(&stats);
        EXPECT_EQ(stats.rays.camera, 21u * 15u * 9u);
        rs.crop = PixelWindow{4, 2, 17, 9};
        rs.tile_size = 3;
        Film crop = Renderer(s, rs).render();
        for (int y = 2; y < 9; ++y)
            for (int x = 4; x < 17; ++x) ASSERT_EQ(crop.beauty[crop.index(x, y)], full.beauty[full.index(x, y)]);
    }
}

TEST(AaSampling, TentSamplingCoversTheFilterSupport) {
    // The inverse CDF maps [0, 1) monotonically onto [-1, 1) with the tent's quantiles.
    EXPECT_FLOAT_EQ(sample_tent(0.f), -1.f);
    EXPECT_FLOAT_EQ(sample_tent(0.5f), 0.f);
    EXPECT_NEAR(sample_tent(0.125f), -0.5f, 1e-6f);
    EXPECT_NEAR(sample_tent(0.875f), 0.5f, 1e-6f);
    float previous = -2.f;
    for (int i = 0; i < 1000; ++i) {
        const float t = sample_tent(float(i) / 1000.f);
        EXPECT_GT(t, previous);
        previous = t;
    }
}

TEST(AaSampling, AovsComeFromThePixelCentreInEveryMode) {
    const Scene s = busy_scene();
    RenderSettings center = settings(17, 11, AaMode::Center);
    center.aovs = AovSet{true, true, true, true, true, true};
    const Film want = Renderer(s, center).render();
    for (AaMode mode : {AaMode::Corners, AaMode::Adaptive, AaMode::Stratified}) {
        RenderSettings rs = center;
        rs.aa.mode = mode;
        rs.aa.spp = 4;
        RenderStats stats;
        const Film got = Renderer(s, rs).render(&stats);
        EXPECT_EQ(stats.rays.aov_probe, 17u * 11u) << aa_mode_name(mode);
        EXPECT_EQ(got.depth, want.depth) << aa_mode_name(mode);
        EXPECT_EQ(got.prim_id, want.prim_id) << aa_mode_name(mode);
        EXPECT_EQ(got.inst_id, want.inst_id) << aa_mode_name(mode);
        ASSERT_EQ(got.aa_samples.size(), got.beauty.size());
        for (float n : got.aa_samples) {
            if (mode == AaMode::Adaptive) {
                ASSERT_TRUE(n >= 4.f && n <= 81.f) << n;
            } else {
                ASSERT_EQ(n, 4.f);  // corners: 4; stratified: spp = 4
            }
        }
    }
    for (float n : want.aa_samples) ASSERT_EQ(n, 1.f);
}

TEST(AaSampling, SplitTestEqualsTheContrastAgainstTheThreshold) {
    // aa_exceeds() decides most squares from slope bounds of the sRGB curve; it must answer exactly
    // aa_contrast() > threshold, including thresholds equal to (or one ulp around) the contrast
    // itself, values beyond [0, 1], both sides of the curve's linear segment, flat channels.
    std::mt19937 rng(6);
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    auto value = [&](float base) -> float {
        switch (rng() % 6) {
            case 0: return base;                                          // flat against the base
            case 1: return base + (unit(rng) - 0.5f) * 1e-3f;             // barely different
            case 2: return base + (unit(rng) - 0.5f) * 0.05f;             // near the thresholds
            case 3: return unit(rng) * 0.01f;                             // around 0.0031308
            case 4: return unit(rng) * 1.5f - 0.1f;                       // clamped at both ends
            default: return unit(rng);
        }
    };
    const float thresholds[] = {-0.1f, 0.f, 1e-6f, 1e-4f, 0.0125f, 0.025f, 0.05f, 0.1f, 0.2f, 0.5f, 1.f};
    int nonflat = 0, splits = 0, checks = 0;
    for (int n = 0; n < 200000; ++n) {
        const float base = rng() % 4 == 0 ? unit(rng) * 0.006f : unit(rng);
        Color corner[4];
        for (Color& c : corner) c = Color(value(base), value(base), value(base));
        const float contrast = aa_contrast(corner[0], corner[1], corner[2], corner[3]);
        auto check = [&](float t) {
            const bool want = contrast > t;
            ASSERT_EQ(aa_exceeds(corner[0], corner[1], corner[2], corner[3], t), want)
                << "contrast " << contrast << " threshold " << t << " corners " << corner[0][0] << " " << corner[1][0]
                << " " << corner[2][0] << " " << corner[3][0];
            splits += want;
            ++checks;
        };
        for (float t : thresholds) check(t);
        for (float t : {contrast, std::nextafter(contrast, -1.f), std::nextafter(contrast, 2.f)}) check(t);
        nonflat += contrast > 0.f;
    }
    // Both answers occur often, so the comparison above tested something.
    EXPECT_GT(splits, checks / 10);
    EXPECT_LT(splits, checks - checks / 10);
    EXPECT_GT(nonflat, 1000);
}

TEST(AaSampling, BadSettingsAreErrors) {
    const Scene s = flat_scene();
    RenderSettings rs = settings(8, 8, AaMode::Stratified);
    rs.aa.spp = 8;  // not k*k
    EXPECT_THROW(Renderer(s, rs), Error);
    rs.aa.spp = 4;
    rs.aa.depth = 9;
    EXPECT_THROW(Renderer(s, rs), Error);
    EXPECT_THROW(parse_aa_mode("supersample"), Error);
    EXPECT_THROW(parse_pixel_filter("gaussian"), Error);
    EXPECT_EQ(parse_aa_mode("adaptive"), AaMode::Adaptive);
}

}  // namespace
}  // namespace whitted
