// The one threading layer: items (tiles) over a fixed set of worker threads, each tracing with
// flush-to-zero on (fp_mode.h). Results never depend on which worker ran an item, so images are
// identical for any thread count (pbrt-v4's ParallelFor2D).
#pragma once

#include <cstddef>
#include <functional>
#include <memory>

namespace whitted {

/// The worker count a `threads` setting means: itself when positive, else all hardware threads.
int resolve_threads(int threads);

class WorkerPool {
public:
    /// `threads` workers, the calling thread among them; 0 = all hardware threads.
    explicit WorkerPool(int threads);
    ~WorkerPool();
    WorkerPool(const WorkerPool&) = delete;
    WorkerPool& operator=(const WorkerPool&) = delete;

    /// Number of workers: the `worker` ids for_each passes are 0 .. size() - 1.
    int size() const { return m_size; }

    /// Runs body(item, worker) for every item in [0, count), one item per task, and returns when
    /// all are done. `worker` names the thread running it (for per-thread state); every worker
    /// runs in FTZ/DAZ mode, and each thread's own mode is restored when it leaves.
    void for_each(size_t count, const std::function<void(size_t item, int worker)>& body);

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
    int m_size = 1;
};

}  // namespace whitted
