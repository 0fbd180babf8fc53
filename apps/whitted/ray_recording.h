// Ray recording for the benchmarks: a decorator of an Accelerator that logs every query a render
// makes, so `bench skip` (the Whitted overhead) and `bench accel` (incoherent rays recorded from a
// real render's secondary rays) can replay exactly the rays a render traced.
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <string>
#include <vector>

#include "renderer/accel/accelerator.h"

namespace whitted::app {

struct RecordedRay {
    Ray ray;
    RayKind kind;
    bool shadow;  ///< a transmittance query (else closest hit)
};

/// Forwards every query to `inner` and keeps a per-thread log of the rays.
class RecordingAccelerator final : public Accelerator {
public:
    explicit RecordingAccelerator(const Accelerator& inner) : m_inner(inner) {}
    Hit intersect(const Ray& ray, RayKind kind) const override {
        m_log.local().push_back({ray, kind, false});
        return m_inner.intersect(ray, kind);
    }
    Color transmittance(const Ray& ray) const override {
        m_log.local().push_back({ray, RayKind::Shadow, true});
        return m_inner.transmittance(ray);
    }
    std::string name() const override { return m_inner.name(); }
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

}  // namespace whitted::app
