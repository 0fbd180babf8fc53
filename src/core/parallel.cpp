#include "core/parallel.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_scheduler_observer.h>

#include <optional>

#include "core/fp_mode.h"

// ThreadSanitizer does not see TBB's fork and join (TBB is not instrumented): made visible by hand.
#if defined(__has_feature)
#if __has_feature(thread_sanitizer)
#include <sanitizer/tsan_interface.h>
#define RT_TSAN_RELEASE(p) __tsan_release(p)
#define RT_TSAN_ACQUIRE(p) __tsan_acquire(p)
#endif
#endif
#ifndef RT_TSAN_RELEASE
#define RT_TSAN_RELEASE(p) ((void)(p))
#define RT_TSAN_ACQUIRE(p) ((void)(p))
#endif

namespace whitted {

namespace {

/// FTZ/DAZ in every thread while it works in the arena: set on entry, the thread's own mode
/// restored on exit (TBB's workers serve other arenas too).
class FtzObserver final : public tbb::task_scheduler_observer {
public:
    explicit FtzObserver(tbb::task_arena& arena) : tbb::task_scheduler_observer(arena) { observe(true); }
    ~FtzObserver() override { observe(false); }
    void on_scheduler_entry(bool) override { in_arena().emplace(); }
    void on_scheduler_exit(bool) override { in_arena().reset(); }

private:
    static std::optional<ScopedFlushDenormals>& in_arena() {
        thread_local std::optional<ScopedFlushDenormals> scope;
        return scope;
    }
};

}  // namespace

struct WorkerPool::Impl {
    explicit Impl(int threads) : arena(threads), observer(arena) {}
    tbb::task_arena arena;
    FtzObserver observer;
};

int resolve_threads(int threads) { return threads > 0 ? threads : tbb::this_task_arena::max_concurrency(); }

WorkerPool::WorkerPool(int threads) {
    m_size = resolve_threads(threads);
    m_impl = std::make_unique<Impl>(m_size);
}

WorkerPool::~WorkerPool() = default;

void WorkerPool::for_each(size_t count, const std::function<void(size_t, int)>& body) {
    const ScopedFlushDenormals ftz;  // the calling thread works too (arena.execute)
    char fork_token = 0, join_token = 0;
    RT_TSAN_RELEASE(&fork_token);
    m_impl->arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 1), [&](const tbb::blocked_range<size_t>& range) {
            RT_TSAN_ACQUIRE(&fork_token);
            const int worker = tbb::this_task_arena::current_thread_index();
            for (size_t item = range.begin(); item != range.end(); ++item) body(item, worker);
            RT_TSAN_RELEASE(&join_token);
        });
    });
    RT_TSAN_ACQUIRE(&join_token);
}

}  // namespace whitted
