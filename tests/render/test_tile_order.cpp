// The order tiles are handed out in (docs/distributed.md): Renderer::tile_costs() estimates each
// tile's work, render_frame hands the dearest out first and guides helpers' batches by the work
// left; none of it may change a pixel.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <optional>
#include <vector>

#include "core/error.h"
#include "integrator/render.h"
#include "scene/scene_builder.h"
#include "session/frame_render.h"

namespace whitted {
namespace {

/// A lit floor filling the lower half of the view (the upper half is background), a mirror box
/// and a glass box on it.
Scene floor_mirror_glass() {
    Scene s;
    WhittedCoeffs floor;
    floor.kd = floor.ka = Color(0.6f, 0.55f, 0.5f);
    add_mesh(s, make_quad({-50, -5, 0}, {50, -5, 0}, {50, 200, 0}, {-50, 200, 0}, add_classic_material(s, floor)));
    WhittedCoeffs mirror;
    mirror.kr = Color(0.8f);
    mirror.kd = mirror.ka = Color(0.1f);
    add_mesh(s, make_box({-2.5f, 0.5f, 0}, {-1.f, 1.5f, 1.5f}, add_classic_material(s, mirror)));
    WhittedCoeffs glass;
    glass.kt = Color(0.9f);
    glass.kr = Color(0.05f);
    glass.ior = 1.5f;
    add_mesh(s, make_box({0.5f, 0.5f, 0}, {2.f, 1.5f, 1.2f}, add_classic_material(s, glass)));
    s.lights.push_back(point_light({2, -3, 5}, 30.f));
    s.lights.push_back(point_light({-3, -2, 4}, 15.f));
    // Level with the floor's far edge: the horizon across the middle of the image.
    s.cameras.push_back(make_camera(CameraType::Perspective, {0, -6, 0.6}, {0, 1, 0}, {0, 0, 1}, 0.7));
    return s;
}

RenderSettings settings(int threads, AaMode mode) {
    RenderSettings rs;
    rs.width = 96;
    rs.height = 64;
    rs.tile_size = 16;
    rs.threads = threads;
    rs.aa.mode = mode;
    rs.aovs = AovSet{true, true, false, true, false, true};
    return rs;
}

bool same_pixels(const Film& a, const Film& b) {
    return a.beauty.size() == b.beauty.size() &&
           std::memcmp(a.beauty.data(), b.beauty.data(), a.beauty.size() * sizeof(Color)) == 0 &&
           std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)) == 0 &&
           a.prim_id == b.prim_id && a.aa_samples == b.aa_samples;
}

TEST(TileOrder, CostsAreDeterministicAndFollowTheWork) {
    const Scene s = floor_mirror_glass();
    const Renderer one(s, settings(1, AaMode::Center));
    const Renderer three(s, settings(3, AaMode::Center));
    const std::vector<double> costs = one.tile_costs();
    ASSERT_EQ(costs.size(), one.tiles().size());
    EXPECT_EQ(costs, one.tile_costs());
    EXPECT_EQ(costs, three.tile_costs());
    // Top row: background only (one ray per probe); bottom row: the floor (a camera ray and a
    // shadow ray per light), the glass and mirror boxes (their trees) in between.
    const size_t columns = 96 / 16;
    const double top = *std::max_element(costs.begin(), costs.begin() + columns);
    const double floor = *std::min_element(costs.end() - columns, costs.end());
    EXPECT_EQ(top, 256.0);  // 16 x 16 pixels, one ray each
    EXPECT_GT(floor, 2.5 * top);
    EXPECT_GT(*std::max_element(costs.begin(), costs.end()), floor);
    EXPECT_THROW(one.tile_costs(1), Error);
}

TEST(TileOrder, AdaptiveCostsCountTheEdges) {
    // Under adaptive sampling a tile across the horizon (an edge the probes see) costs more,
    // relative to a flat tile of background, than under one sample per pixel.
    const Scene s = floor_mirror_glass();
    const Renderer centre(s, settings(1, AaMode::Center));
    const Renderer adaptive(s, settings(1, AaMode::Adaptive));
    const std::vector<double> c = centre.tile_costs(), a = adaptive.tile_costs();
    const std::vector<TileRect> tiles = centre.tiles();
    const Film image = centre.render();
    size_t edge_tiles = 0;
    for (size_t i = 0; i < tiles.size(); ++i) {
        EXPECT_GE(a[i], c[i]);
        if (a[i] > c[i]) ++edge_tiles;
    }
    EXPECT_GT(edge_tiles, 0u);
    EXPECT_LT(edge_tiles, tiles.size());
    EXPECT_EQ(a[0], c[0]);  // the top-left tile: background only, no edge
}

/// A helper rendering in this process what it takes, batch by batch, and recording the batches.
class RecordingHelper : public TileHelpers {
public:
    explicit RecordingHelper(const Renderer& r, int workers = 1) : m_renderer(r), m_workers(workers) {}
    void serve(const TakeTiles& take, const TileDone& give, RenderStats& stats, const std::atomic<bool>*) override {
        for (;;) {
            const std::vector<size_t> batch = take(4, 0.3);
            if (batch.empty()) return;
            batches.push_back(batch);
            size_t i = 0;
            m_renderer.render_tiles([&]() -> std::optional<size_t> {
                return i < batch.size() ? std::optional(batch[i++]) : std::nullopt;
            }, give, &stats);
        }
    }
    int workers() const override { return m_workers; }
    std::vector<std::vector<size_t>> batches;

private:
    const Renderer& m_renderer;
    int m_workers;
};

TEST(TileOrder, DearestFirstWithGuidedBatchesMakesTheSameImage) {
    const Scene s = floor_mirror_glass();
    for (const AaMode mode : {AaMode::Adaptive, AaMode::Corners}) {
        const Renderer r(s, settings(1, mode));
        const Film reference = r.render();
        for (const TileOrder order : {TileOrder::ExpensiveFirst, TileOrder::Frame}) {
            FrameOptions fo;
            fo.order = order;
            // This process's own thread and the helper (the calling thread) race for the tiles: on
            // a loaded machine the own thread can take them all before the helper's first call.
            // Repeat until the helper has served (every frame must still be the same image).
            std::optional<RecordingHelper> helper;
            FrameResult frame;
            for (int attempt = 0; attempt < 50 && (!helper || helper->batches.empty()); ++attempt) {
                helper.emplace(r);
                frame = render_frame(r, fo, &*helper);
                EXPECT_TRUE(frame.missing().empty());
                EXPECT_TRUE(same_pixels(reference, frame.film)) << aa_mode_name(mode);
            }
            ASSERT_FALSE(helper->batches.empty()) << "the helper never got a tile in 50 frames";
            // The helper's tiles, in the order it got them: dearest first (or frame order).
            std::vector<size_t> got;
            for (const auto& b : helper->batches) got.insert(got.end(), b.begin(), b.end());
            if (order == TileOrder::Frame) {
                EXPECT_TRUE(frame.tile_cost.empty());
                EXPECT_TRUE(std::is_sorted(got.begin(), got.end()));
            } else {
                ASSERT_EQ(frame.tile_cost.size(), r.tiles().size());
                EXPECT_TRUE(std::is_sorted(got.begin(), got.end(), [&](size_t a, size_t b) {
                    return frame.tile_cost[a] > frame.tile_cost[b];
                }));
            }
            // Guided: a batch stops once its work reaches 0.3 of the work left (which is at most
            // what earlier batches left: this process's own tiles take from it too).
            auto work = [&](size_t t) { return frame.tile_cost.empty() ? 1.0 : frame.tile_cost[t]; };
            double left = 0.0;
            for (size_t t = 0; t < r.tiles().size(); ++t) left += work(t);
            size_t largest = 0;
            for (const auto& b : helper->batches) {
                double before_last = 0.0;
                for (size_t i = 0; i + 1 < b.size(); ++i) before_last += work(b[i]);
                EXPECT_LT(before_last, 0.3 * left + 1e-9);
                EXPECT_LE(b.size(), 4u);
                for (const size_t t : b) left -= work(t);
                largest = std::max(largest, b.size());
            }
            EXPECT_GT(largest, 1u);
        }
    }
}

TEST(TileOrder, AutoEstimatesCostsFromEightWorkersOn) {
    const Scene s = floor_mirror_glass();
    const Renderer r(s, settings(1, AaMode::Adaptive));
    for (const int helpers : {1, 6, 7, 20}) {
        FrameOptions fo;  // TileOrder::Auto
        RecordingHelper helper(r, helpers);
        const FrameResult frame = render_frame(r, fo, &helper);
        EXPECT_EQ(!frame.tile_cost.empty(), 1 + helpers >= kExpensiveFirstWorkers) << helpers << " helper workers";
    }
    FrameOptions fo;
    EXPECT_TRUE(render_frame(r, fo).tile_cost.empty());  // one thread alone
}

}  // namespace
}  // namespace whitted
