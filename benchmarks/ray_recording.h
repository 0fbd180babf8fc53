// Ray recording for the benchmarks: a decorator of an Accelerator that logs every query a render
// makes, so `bench skip` (the Whitted overhead) and `bench accel` (incoherent rays recorded from a
// real render's secondary rays) can replay exactly the rays a render traced. Batch queries
// (Accelerator::intersect over a span: the integrator's rows of camera rays) are forwarded as
// batches and their boundaries kept, so a replay can trace them as batches too (packets where the
// render used packets); batch shadow queries likewise.
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "benchmarks/bench_timing.h"
#include "accel/accelerator.h"

namespace whitted::app {

struct RecordedRay {
    Ray ray;
    RayKind kind;
    bool shadow;          ///< a transmittance query (else closest hit)
    uint32_t batch = 1;   ///< first ray of a query: rays in that query (1 = single-ray); 0 = later
                          ///< ray of a batch query
};

/// Replays `rays[begin, end)` (which must start at a query boundary) through `accel` query by
/// query: batches as one batch query (cut at `end`), the others one ray at a time. Returns a sum of
/// the results (for the caller to keep, so nothing is optimised away). `batch`, `hits`: scratch.
inline float replay(const Accelerator& accel, const std::vector<RecordedRay>& rays, size_t begin, size_t end,
                    std::vector<Ray>& batch, std::vector<Hit>& hits) {
    float sink = 0.f;
    for (size_t i = begin; i < end;) {
        const RecordedRay& rr = rays[i];
        if (rr.batch > 1) {
            const size_t n = std::min<size_t>(rr.batch, end - i);
            batch.clear();
            for (size_t k = i; k < i + n; ++k) batch.push_back(rays[k].ray);
            if (rr.shadow) {
                thread_local std::vector<Color> through;
                through.resize(batch.size());
                accel.transmittance(batch, through);
                for (const Color& c : through) sink += c.x;
            } else {
                hits.resize(batch.size());
                accel.intersect(batch, rr.kind, hits);
                for (const Hit& h : hits) sink += h.t;
            }
            i += n;
        } else {
            sink += rr.shadow ? accel.transmittance(rr.ray).x : accel.intersect(rr.ray, rr.kind).t;
            ++i;
        }
    }
    return sink;
}

/// Forwards every query to `inner` and keeps a per-thread log of the rays.
class RecordingAccelerator final : public Accelerator {
public:
    explicit RecordingAccelerator(const Accelerator& inner) : m_inner(inner) {}
    Hit intersect(const Ray& ray, RayKind kind) const override {
        m_log.local().push_back({ray, kind, false});
        return m_inner.intersect(ray, kind);
    }
    void intersect(std::span<const Ray> rays, RayKind kind, std::span<Hit> hits) const override {
        std::vector<RecordedRay>& log = m_log.local();
        for (size_t i = 0; i < rays.size(); ++i) log.push_back({rays[i], kind, false, i == 0 ? uint32_t(rays.size()) : 0u});
        m_inner.intersect(rays, kind, hits);
    }
    Color transmittance(const Ray& ray) const override {
        m_log.local().push_back({ray, RayKind::Shadow, true});
        return m_inner.transmittance(ray);
    }
    void transmittance(std::span<const Ray> rays, std::span<Color> out) const override {
        std::vector<RecordedRay>& log = m_log.local();
        for (size_t i = 0; i < rays.size(); ++i)
            log.push_back({rays[i], RayKind::Shadow, true, i == 0 ? uint32_t(rays.size()) : 0u});
        m_inner.transmittance(rays, out);
    }
    std::string name() const override { return m_inner.name(); }
    RayOffsetPolicy ray_offset() const override { return m_inner.ray_offset(); }
    AccelStats stats() const override { return m_inner.stats(); }

    /// All rays, thread by thread (each thread's log keeps its tiles' coherent order).
    std::vector<RecordedRay> rays() const {
        std::vector<RecordedRay> all;
        for (const auto& log : m_log) all.insert(all.end(), log.begin(), log.end());
        return all;
    }

private:
    const Accelerator& m_inner;
    mutable tbb::enumerable_thread_specific<std::vector<RecordedRay>> m_log;
};

/// A decorator of an Accelerator that adds up the ticks spent inside its queries (every thread
/// into one atomic total): the traversal's part of a render, or of a replay of the render's rays.
/// Reading the counter twice per query costs both the same few ns per ray.
class TimingAccelerator final : public Accelerator {
public:
    explicit TimingAccelerator(const Accelerator& inner) : m_inner(inner) {}
    Hit intersect(const Ray& ray, RayKind kind) const override {
        const uint64_t t0 = ticks();
        const Hit h = m_inner.intersect(ray, kind);
        m_ticks.fetch_add(ticks() - t0, std::memory_order_relaxed);
        return h;
    }
    void intersect(std::span<const Ray> rays, RayKind kind, std::span<Hit> hits) const override {
        const uint64_t t0 = ticks();
        m_inner.intersect(rays, kind, hits);
        m_ticks.fetch_add(ticks() - t0, std::memory_order_relaxed);
    }
    Color transmittance(const Ray& ray) const override {
        const uint64_t t0 = ticks();
        const Color c = m_inner.transmittance(ray);
        m_ticks.fetch_add(ticks() - t0, std::memory_order_relaxed);
        return c;
    }
    void transmittance(std::span<const Ray> rays, std::span<Color> out) const override {
        const uint64_t t0 = ticks();
        m_inner.transmittance(rays, out);
        m_ticks.fetch_add(ticks() - t0, std::memory_order_relaxed);
    }
    std::string name() const override { return m_inner.name(); }
    RayOffsetPolicy ray_offset() const override { return m_inner.ray_offset(); }
    AccelStats stats() const override { return m_inner.stats(); }

    uint64_t traversal_ticks() const { return m_ticks.load(); }

private:
    const Accelerator& m_inner;
    mutable std::atomic<uint64_t> m_ticks{0};
};

}  // namespace whitted::app
