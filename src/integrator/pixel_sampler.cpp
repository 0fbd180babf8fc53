#include "integrator/pixel_sampler.h"

#include <tbb/concurrent_hash_map.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <span>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/uninitialized.h"

namespace whitted {

namespace {

/// Adaptive samples on pixel edges (not corners) that lie on a border between two tiles, keyed by
/// their position on the 2^depth lattice of the full image. Each is used by at most the two pixels
/// sharing the edge, in different tiles that may run concurrently: the first request traces it
/// while holding the element's write lock (a concurrent request for the same point waits instead of
/// tracing it again), the second one removes it, so the map only holds the points whose second
/// user has not run yet. Edges inside a tile never come here (see AdaptiveScratch).
class EdgeSamples {
public:
    template <typename Trace>
    Color get(uint64_t key, Trace&& trace) {
        Map::accessor a;
        if (m_map.insert(a, key)) {
            a->second.value = trace();
            a->second.uses = 1;
            return a->second.value;
        }
        const Color value = a->second.value;
        if (++a->second.uses == 2) m_map.erase(a);
        return value;
    }

private:
    struct Entry {
        Color value{0.f};
        int uses = 0;
    };
    using Map = tbb::concurrent_hash_map<uint64_t, Entry>;
    Map m_map;
};

/// Per-thread working memory of the adaptive pass.
/// - One pixel's grid of (2^depth + 1)^2 points; a point is valid when its stamp equals the current
///   generation, so nothing is cleared between pixels.
/// - The edge points a pixel hands to the neighbours it shares an edge with inside the same tile
///   (pixels run row by row): the n - 1 points inside its right edge, read by the next pixel of the
///   row, and inside its bottom edge, read by the pixel below (one slot per tile column). A point
///   the first pixel did not need is marked invalid and the second traces it itself, so tile-inner
///   edges are shared without hashing or locking; only tile borders go through EdgeSamples.
struct AdaptiveScratch {
    std::vector<Color> value;
    std::vector<uint32_t> stamp;
    std::vector<uint32_t> split;       ///< == generation at the centre point of each square that split (squares
                                       ///< of different sizes or places never share a centre)
    uint32_t generation = 0;
    std::vector<int> squares, next;    ///< the squares of the current and next level: top-left grid index
    std::array<uint32_t, WhittedIntegrator::kCameraBatch> pending;  ///< grid indices of the points to trace
    std::array<Ray, WhittedIntegrator::kCameraBatch> pending_rays;  ///< their camera rays
    size_t pending_count = 0;
    float pending_spacing = 1.f;       ///< their footprint (adaptive_point_spacing), the same for the batch
    std::vector<Color> right;          ///< n - 1 points inside the previous pixel's right edge
    std::vector<uint8_t> right_valid;
    std::vector<Color> bottom;         ///< per tile column, n - 1 points inside the bottom edge of the pixel above
    std::vector<uint8_t> bottom_valid;
};

}  // namespace

/// Everything one render shares between its tiles: the camera, the integrator, the window, the
/// corner lattice and the tile-border edge points.
class PixelSampler::Impl {
public:
    Impl(const CameraModel& camera, const WhittedIntegrator& integrator, const PixelWindow& window, int full_width,
         const AovSet& aovs, const AaSettings& aa, float exposure)
        : m_camera(camera), m_integrator(integrator), m_window(window), m_full_width(full_width), m_aovs(aovs),
          m_aa(aa), m_exposure(exposure),
          m_cone(aa.texture_filter == TextureFilter::Mip ? camera.pixel_cone() : RayCone{}), m_n(1 << aa.depth) {
        if (aa.mode == AaMode::Corners || aa.mode == AaMode::Adaptive) {
            const size_t corners = size_t(window.width() + 1) * size_t(window.height() + 1);
            m_lattice.assign(corners, Color(0.f));
            m_corner_state = std::make_unique<std::atomic<uint8_t>[]>(corners);  // value-initialised: kFree
        }
    }

    /// A camera ray's radiance as a sample: exposure-scaled, never NaN/inf (counted, set to 0).
    Color exposed(const Color& radiance) {
        const Color c = radiance * m_exposure;
        if (is_finite(c)) return c;
        ++m_nonfinite;
        return Color(0.f);
    }

    /// The ray cone of a sample whose footprint is `spacing` pixels wide (zero with --texture-filter none).
    RayCone cone(float spacing) const { return RayCone{m_cone.width * spacing, m_cone.spread * spacing}; }

    /// One primary sample at image position (x, y), its texture footprint `spacing` pixels wide.
    Color sample(double x, double y, float spacing, RayCounters& rc, PrimaryInfo* info = nullptr) {
        return exposed(m_integrator.trace(m_camera.generate(x, y), RayKind::Camera, 0, rc, info, cone(spacing)));
    }

    /// Samples traced together by sample_row: a coherent row (the integrator's batch size).
    static constexpr int kRow = int(WhittedIntegrator::kCameraBatch);

    /// Up to kRow camera rays traced as one batch (WhittedIntegrator::trace_camera: Embree packets
    /// in the specialised kernels): out[i] is what sample() gives for rays[i], the same arithmetic
    /// in the same order. `info` may be null; `spacing` as for sample().
    void trace_row(std::span<const Ray> rays, float spacing, Color* out, RayCounters& rc, PrimaryInfo* info = nullptr) {
        const size_t n = rays.size();
        m_integrator.trace_camera(rays, std::span<Color>(out, n), rc, cone(spacing),
                                  info ? std::span<PrimaryInfo>(info, n) : std::span<PrimaryInfo>{});
        for (size_t i = 0; i < n; ++i) out[i] = exposed(out[i]);
    }

    /// n <= kRow samples along an image row, at (x0 + i, y): generated as a row (bit for bit the
    /// rays generate() gives) and traced as one batch.
    void sample_row(int n, double x0, double y, Color* out, RayCounters& rc, PrimaryInfo* info = nullptr) {
        UninitializedArray<Ray, kRow> rays;  // generate_row writes every ray
        const std::span<Ray> row = rays.first(size_t(n));
        m_camera.generate_row(x0, 1.0, y, row);
        trace_row(row, 1.f, out, rc, info);
    }

    /// center: one ray through each pixel centre (it also gives the AOVs), rows of a tile in batches.
    void center_tile(const TileRect& r, RayCounters& rc, Film& out) {
        const bool aovs = m_aovs.needs_first_hit();
        std::array<Color, kRow> c;
        std::array<PrimaryInfo, kRow> info;  // read by finish_pixel only when AOVs are on
        for (int y = r.y0; y < r.y1; ++y)
            for (int x0 = r.x0; x0 < r.x1; x0 += kRow) {
                const int n = std::min(kRow, r.x1 - x0);
                if (aovs) info.fill(PrimaryInfo{});
                sample_row(n, x0 + 0.5, y + 0.5, c.data(), rc, aovs ? info.data() : nullptr);
                for (int i = 0; i < n; ++i) finish_pixel(out, x0 + i, y, c[size_t(i)], 1.f, &info[size_t(i)], rc);
            }
    }

    /// stratified: k x k jittered samples, box or tent filter importance-sampled, equal weights.
    void stratified_tile(const TileRect& r, RayCounters& rc, Film& out) {
        const int k = stratified_side(m_aa.spp);
        const double inv_k = 1.0 / k;
        const float spacing = float(inv_k);  // each sample's footprint: its stratum
        for (int y = r.y0; y < r.y1; ++y)
            for (int x = r.x0; x < r.x1; ++x) {
                // Seeded by the full-image pixel index: crops and tiles see the same jitter.
                const uint64_t pixel = uint64_t(y) * uint64_t(m_full_width) + uint64_t(x);
                // Sample s = j k + i of the pixel, in the order the sum takes them.
                auto position = [&](int s) {
                    const int j = s / k, i = s % k;
                    const uint64_t key = ((pixel << 12 | uint64_t(s)) << 1);
                    const double u = (i + double(hash_to_unit_float(key))) * inv_k;
                    const double v = (j + double(hash_to_unit_float(key | 1))) * inv_k;
                    if (m_aa.filter == PixelFilter::Tent)
                        return std::pair(x + 0.5 + double(sample_tent(float(u))), y + 0.5 + double(sample_tent(float(v))));
                    return std::pair(x + u, y + v);
                };
                Color sum(0.f);
                for (int s0 = 0; s0 < k * k; s0 += kRow) {
                    const int n = std::min(kRow, k * k - s0);
                    UninitializedArray<Ray, kRow> rays;
                    for (int i = 0; i < n; ++i) {
                        const auto [sx, sy] = position(s0 + i);
                        rays.at[i] = m_camera.generate(sx, sy);
                    }
                    UninitializedArray<Color, kRow> c;
                    trace_row(rays.first(size_t(n)), spacing, c.at, rc);
                    for (int i = 0; i < n; ++i) sum += c.at[i];
                }
                finish_pixel(out, x, y, sum * float(1.0 / m_aa.spp), float(m_aa.spp), nullptr, rc);
            }
    }

    /// The lattice corners of a tile (corners, adaptive): its (w+1)(h+1) pixel corners, shared
    /// with the neighbouring tiles along its borders. The tile claims every corner nobody claimed
    /// yet and traces those (runs along a row as camera batches), then waits for the ones other
    /// tiles claimed. A tile traces all its claims before it waits, so a wait always ends (the
    /// claiming tile is tracing); every corner is traced once per sampler.
    void lattice_tile(const TileRect& r, RayCounters& rc) {
        try {
            for (int y = r.y0; y <= r.y1; ++y) {
                int run = 0, run_x0 = 0;  // claimed corners (run_x0 .. run_x0 + run - 1, y) not yet traced
                auto trace_run = [&] {
                    UninitializedArray<Color, kRow> c;
                    sample_row(run, double(run_x0), double(y), c.at, rc);
                    for (int i = 0; i < run; ++i) {
                        const size_t k = lattice_index(run_x0 + i, y);
                        m_lattice[k] = c.at[i];
                        m_corner_state[k].store(kReady, std::memory_order_release);
                    }
                    run = 0;
                };
                for (int x = r.x0; x <= r.x1; ++x) {
                    uint8_t expected = kFree;
                    if (!m_corner_state[lattice_index(x, y)].compare_exchange_strong(expected, kClaimed,
                                                                                     std::memory_order_relaxed)) {
                        if (run > 0) trace_run();
                        continue;
                    }
                    if (run == 0) run_x0 = x;
                    if (++run == kRow) trace_run();
                }
                if (run > 0) trace_run();
            }
        } catch (...) {
            m_abandoned.store(true);  // corners this tile claimed will never be ready: release the waiters
            throw;
        }
        for (int y = r.y0; y <= r.y1; ++y)
            for (int x = r.x0; x <= r.x1; ++x) {
                const std::atomic<uint8_t>& state = m_corner_state[lattice_index(x, y)];
                while (state.load(std::memory_order_acquire) != kReady) {
                    if (m_abandoned.load()) throw Error("a tile sharing this tile's corners failed");
                    std::this_thread::yield();
                }
            }
    }

    /// corners: pixel = mean of its 4 lattice corners.
    void corners_tile(const TileRect& r, RayCounters& rc, Film& out) {
        for (int y = r.y0; y < r.y1; ++y)
            for (int x = r.x0; x < r.x1; ++x) {
                const Color c = (corner(x, y) + corner(x + 1, y) + corner(x, y + 1) + corner(x + 1, y + 1)) * 0.25f;
                finish_pixel(out, x, y, c, 4.f, nullptr, rc);
            }
    }

    /// adaptive (Whitted 1980): recursive subdivision of each pixel square from its lattice corners.
    void adaptive_tile(const TileRect& r, RayCounters& rc, AdaptiveScratch& scratch, Film& out) {
        const size_t points = size_t(m_n + 1) * size_t(m_n + 1);
        const size_t inner = size_t(m_n - 1);  // points inside one pixel edge
        if (scratch.value.size() != points) {
            scratch.value.assign(points, Color(0.f));
            scratch.stamp.assign(points, 0u);
            scratch.split.assign(points, 0u);
            scratch.generation = 0;
            scratch.right.assign(inner, Color(0.f));
            scratch.right_valid.assign(inner, 0);
        }
        if (scratch.bottom.size() < size_t(r.x1 - r.x0) * inner) {
            scratch.bottom.resize(size_t(r.x1 - r.x0) * inner);
            scratch.bottom_valid.resize(size_t(r.x1 - r.x0) * inner);
        }
        for (int y = r.y0; y < r.y1; ++y)
            for (int x = r.x0; x < r.x1; ++x) {
                // Most pixels do not split: decide that from the lattice alone and skip the grid.
                // What refine() and combine() would give for them: the mean of the 4 corners (area 1),
                // 4 points, no edge point to hand over.
                const Color& c00 = corner(x, y);
                const Color& c10 = corner(x + 1, y);
                const Color& c01 = corner(x, y + 1);
                const Color& c11 = corner(x + 1, y + 1);
                if (m_aa.depth == 0 || !aa_exceeds(c00, c10, c01, c11, m_aa.threshold)) {
                    const auto below = scratch.bottom_valid.begin() + std::ptrdiff_t(size_t(x - r.x0) * inner);
                    std::fill_n(scratch.right_valid.begin(), inner, uint8_t(0));
                    std::fill_n(below, inner, uint8_t(0));
                    finish_pixel(out, x, y, (c00 + c10 + c01 + c11) * 0.25f, 4.f, nullptr, rc);
                    continue;
                }
                if (++scratch.generation == 0) {  // wrapped: invalidate every stamp once
                    std::fill(scratch.stamp.begin(), scratch.stamp.end(), 0u);
                    std::fill(scratch.split.begin(), scratch.split.end(), 0u);
                    scratch.generation = 1;
                }
                PixelRecursion p{x, y, &r, 0, false};
                refine(p, scratch, rc);
                const Color c = combine(scratch, 0, 0, m_n);
                if (p.split) ++m_subdivided;
                hand_over_edges(p, scratch);
                finish_pixel(out, x, y, c, float(p.points), nullptr, rc);
            }
    }

    uint64_t nonfinite() const { return m_nonfinite.load(); }
    uint64_t subdivided() const { return m_subdivided.load(); }
    AaMode mode() const { return m_aa.mode; }

    /// Per-worker adaptive scratch, each on its own cache lines.
    struct alignas(64) WorkerScratch {
        AdaptiveScratch value;
    };
    std::vector<WorkerScratch> scratch;

private:
    struct PixelRecursion {
        int x, y;           ///< pixel
        const TileRect* tile;   ///< the tile it belongs to
        int points;         ///< distinct sample points used
        bool split;         ///< the pixel square was split
    };

    size_t lattice_index(int x, int y) const {
        return size_t(y - m_window.y0) * size_t(m_window.width() + 1) + size_t(x - m_window.x0);
    }
    const Color& corner(int x, int y) const { return m_lattice[lattice_index(x, y)]; }

    /// Requests sample (i, j) of pixel p's (n+1) x (n+1) grid, at most once per pixel: a lattice
    /// corner or a handed-over edge point is stored at once, a point on a tile border is fetched
    /// or traced through EdgeSamples, every other point is queued for the next flush().
    void point(PixelRecursion& p, AdaptiveScratch& s, RayCounters& rc, int i, int j) {
        const size_t k = size_t(j) * size_t(m_n + 1) + size_t(i);
        if (s.stamp[k] == s.generation) return;
        s.stamp[k] = s.generation;
        ++p.points;
        const int n = m_n;
        const bool on_x = i == 0 || i == n, on_y = j == 0 || j == n;
        if (on_x && on_y) s.value[k] = corner(p.x + (i == n), p.y + (j == n));
        else if (on_x || on_y) {
            if (!edge_point(p, s, rc, i, j, s.value[k])) queue(p, s, rc, i, j);
        } else {
            queue(p, s, rc, i, j);
        }
    }

    /// Queues point (i, j) of pixel p for tracing in the next batch (flushed when full).
    void queue(const PixelRecursion& p, AdaptiveScratch& s, RayCounters& rc, int i, int j) {
        const float spacing = adaptive_point_spacing(i, j, m_aa.depth);
        if (s.pending_count > 0 && spacing != s.pending_spacing) flush(s, rc);  // one footprint per batch
        s.pending_spacing = spacing;
        s.pending[s.pending_count] = uint32_t(j * (m_n + 1) + i);
        s.pending_rays[s.pending_count] = m_camera.generate(p.x + double(i) / m_n, p.y + double(j) / m_n);
        if (++s.pending_count == s.pending.size()) flush(s, rc);
    }

    /// Traces the queued points as one camera batch (WhittedIntegrator::trace_camera: Embree
    /// packets; the same radiance as sample() gives for each) and stores them in the grid.
    void flush(AdaptiveScratch& s, RayCounters& rc) {
        if (s.pending_count == 0) return;
        UninitializedArray<Color, WhittedIntegrator::kCameraBatch> c;
        trace_row(std::span<const Ray>(s.pending_rays.data(), s.pending_count), s.pending_spacing, c.at, rc);
        for (size_t q = 0; q < s.pending_count; ++q) s.value[s.pending[q]] = c.at[q];
        s.pending_count = 0;
    }

    /// A point inside one of pixel p's edges (i or j is 0 or n, not both). The edge is either on the
    /// window's border (no neighbour: we trace it), inside the tile (the left or upper pixel, which
    /// ran before, handed it over when it had traced it; the right or lower one will take it from
    /// us), or on a tile border (shared through EdgeSamples with the pixel in the other tile). Stores
    /// the value in `out` and returns true when it has one; false = this pixel must trace it (the
    /// caller queues it with the pixel's batch).
    bool edge_point(PixelRecursion& p, AdaptiveScratch& s, RayCounters& rc, int i, int j, Color& out) {
        const int n = m_n;
        const TileRect& r = *p.tile;
        const PixelWindow& w = m_window;
        // Is the pixel across the edge in this tile, and in the window at all?
        bool in_tile = false, in_window = false;
        if (i == 0) {  // left edge: the previous pixel of the row handed it over
            in_tile = p.x > r.x0;
            in_window = p.x > w.x0;
            if (in_tile) {
                if (!s.right_valid[size_t(j - 1)]) return false;
                out = s.right[size_t(j - 1)];
                return true;
            }
        } else if (j == 0) {  // top edge: the pixel above handed it over
            in_tile = p.y > r.y0;
            in_window = p.y > w.y0;
            const size_t slot = size_t(p.x - r.x0) * size_t(n - 1) + size_t(i - 1);
            if (in_tile) {
                if (!s.bottom_valid[slot]) return false;
                out = s.bottom[slot];
                return true;
            }
        } else if (i == n) {  // right edge
            in_tile = p.x + 1 < r.x1;
            in_window = p.x + 1 < w.x1;
        } else {  // bottom edge
            in_tile = p.y + 1 < r.y1;
            in_window = p.y + 1 < w.y1;
        }
        if (in_tile || !in_window) return false;  // hand_over_edges() passes it on / nobody else needs it
        // A tile border: traced alone, inside EdgeSamples' lock, so a concurrent tile never traces it twice.
        const uint64_t gx = uint64_t(p.x) * uint64_t(n) + uint64_t(i), gy = uint64_t(p.y) * uint64_t(n) + uint64_t(j);
        out = m_edges.get(gx << 32 | gy, [&] {
            return sample(p.x + double(i) / n, p.y + double(j) / n, adaptive_point_spacing(i, j, m_aa.depth), rc);
        });
        return true;
    }

    /// After pixel p: passes the points inside its right and bottom edges (valid when traced) to
    /// the pixels that will read them in edge_point().
    void hand_over_edges(const PixelRecursion& p, AdaptiveScratch& s) const {
        const int n = m_n;
        const size_t stride = size_t(n + 1);
        for (int t = 1; t < n; ++t) {
            const size_t kr = size_t(t) * stride + size_t(n);    // right edge, (n, t)
            const size_t kb = size_t(n) * stride + size_t(t);    // bottom edge, (t, n)
            const size_t slot = size_t(p.x - p.tile->x0) * size_t(n - 1) + size_t(t - 1);
            s.right_valid[size_t(t - 1)] = s.stamp[kr] == s.generation;
            s.right[size_t(t - 1)] = s.value[kr];
            s.bottom_valid[slot] = s.stamp[kb] == s.generation;
            s.bottom[slot] = s.value[kb];
        }
    }

    /// Whitted's recursion for pixel p, one level at a time so that the new points of a level are
    /// traced together (camera batches) rather than one by one: a square of side `size` grid steps
    /// at `level` splits into 4 when level < depth and its corners differ by more than the
    /// threshold. The squares visited, the split decisions and the points traced are those of the
    /// depth-first recursion (a point's value does not depend on when it is traced); the split
    /// squares are marked at their centre point for combine().
    void refine(PixelRecursion& p, AdaptiveScratch& s, RayCounters& rc) {
        const int stride = m_n + 1;
        auto value = [&](int i, int j) -> const Color& { return s.value[size_t(j * stride + i)]; };
        for (int i : {0, m_n})
            for (int j : {0, m_n}) point(p, s, rc, i, j);
        s.squares.assign(1, 0);
        for (int level = 0, size = m_n; level < m_aa.depth && !s.squares.empty(); ++level, size /= 2) {
            const int h = size / 2;
            s.next.clear();
            for (const int sq : s.squares) {
                const int i = sq % stride, j = sq / stride;
                if (!aa_exceeds(value(i, j), value(i + size, j), value(i, j + size), value(i + size, j + size),
                                m_aa.threshold))
                    continue;
                if (level == 0) p.split = true;
                s.split[size_t((j + h) * stride + i + h)] = s.generation;
                // The children's corners: the 4 edge midpoints and the centre are new.
                point(p, s, rc, i + h, j);
                point(p, s, rc, i, j + h);
                point(p, s, rc, i + h, j + h);
                point(p, s, rc, i + size, j + h);
                point(p, s, rc, i + h, j + size);
                for (const int child : {sq, sq + h, sq + h * stride, sq + h * stride + h}) s.next.push_back(child);
            }
            flush(s, rc);  // the next level's contrasts read these points
            std::swap(s.squares, s.next);
        }
    }

    /// Area-weighted radiance of the sub-square with top-left grid point (i, j) and side `size`
    /// grid steps, as refine() subdivided it: the sum of its 4 children when it split, else the
    /// mean of its 4 corners. The additions run in the depth-first order of Whitted's formula.
    Color combine(const AdaptiveScratch& s, int i, int j, int size) const {
        const size_t stride = size_t(m_n + 1);
        if (size > 1 && s.split[size_t(j + size / 2) * stride + size_t(i + size / 2)] == s.generation) {
            const int h = size / 2;
            return combine(s, i, j, h) + combine(s, i + h, j, h) + combine(s, i, j + h, h) + combine(s, i + h, j + h, h);
        }
        // Leaf: mean of the corners times the area (a power of 2, exact) as a fraction of the pixel.
        auto v = [&](int a, int b) -> const Color& { return s.value[size_t(b) * stride + size_t(a)]; };
        const float area = float(size) * float(size) / (float(m_n) * float(m_n));
        return (v(i, j) + v(i + size, j) + v(i, j + size) + v(i + size, j + size)) * (0.25f * area);
    }

    /// Stores a pixel and its AOVs (probing the pixel centre when the mode traced no centre ray).
    void finish_pixel(Film& out, int x, int y, const Color& c, float samples, const PrimaryInfo* info,
                      RayCounters& rc) {
        const size_t i = out.index(x, y);
        out.beauty[i] = c;
        if (out.aovs.aa_samples) out.aa_samples[i] = samples;
        if (!out.aovs.needs_first_hit()) return;
        PrimaryInfo probed;
        if (!info) {
            m_integrator.probe(m_camera.generate(x + 0.5, y + 0.5), rc, probed);
            info = &probed;
        }
        if (out.aovs.depth) out.depth[i] = info->depth;
        if (out.aovs.normal) out.normal[i] = info->normal;
        if (out.aovs.albedo) out.albedo[i] = info->albedo;
        if (out.aovs.prim_id) out.prim_id[i] = info->prim;
        if (out.aovs.inst_id) out.inst_id[i] = info->inst;
    }

    /// A lattice corner's state: nobody traces it yet, a tile traces it, its value is in m_lattice.
    static constexpr uint8_t kFree = 0, kClaimed = 1, kReady = 2;

    const CameraModel& m_camera;
    const WhittedIntegrator& m_integrator;
    const PixelWindow m_window;          ///< the rendered region (image or crop)
    const int m_full_width;              ///< the image's width (stratified seeds by full-image pixel)
    const AovSet m_aovs;
    const AaSettings& m_aa;
    const float m_exposure;
    const RayCone m_cone;  ///< a pixel-wide footprint (zero: --texture-filter none)
    const int m_n;                       ///< adaptive grid steps per pixel side, 2^depth
    std::vector<Color> m_lattice;        ///< (w+1) x (h+1) pixel-corner samples of the window
    std::unique_ptr<std::atomic<uint8_t>[]> m_corner_state;  ///< per corner: kFree, kClaimed, kReady
    std::atomic<bool> m_abandoned{false};  ///< a tile failed while it held claimed corners
    EdgeSamples m_edges;
    std::atomic<uint64_t> m_nonfinite{0};
    std::atomic<uint64_t> m_subdivided{0};
};

PixelSampler::PixelSampler(const CameraModel& camera, const WhittedIntegrator& integrator, const PixelWindow& window,
                           int full_width, const AovSet& aovs, const AaSettings& aa, float exposure, int workers)
    : m_impl(std::make_unique<Impl>(camera, integrator, window, full_width, aovs, aa, exposure)) {
    m_impl->scratch.resize(size_t(std::max(workers, 1)));
}

PixelSampler::~PixelSampler() = default;

void PixelSampler::render_tile(const TileRect& tile, int worker, RayCounters& rays, Film& out) {
    Impl& s = *m_impl;
    switch (s.mode()) {
        case AaMode::Center: s.center_tile(tile, rays, out); break;
        case AaMode::Stratified: s.stratified_tile(tile, rays, out); break;
        case AaMode::Corners:
            s.lattice_tile(tile, rays);
            s.corners_tile(tile, rays, out);
            break;
        case AaMode::Adaptive:
            s.lattice_tile(tile, rays);
            s.adaptive_tile(tile, rays, s.scratch[size_t(worker)].value, out);
            break;
    }
}

uint64_t PixelSampler::nonfinite() const { return m_impl->nonfinite(); }
uint64_t PixelSampler::subdivided() const { return m_impl->subdivided(); }

}  // namespace whitted
