#include "session/mpi_frame.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <deque>
#include <iterator>
#include <list>
#include <mutex>
#include <string>
#include <thread>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "core/error.h"
#include "core/log.h"
#include "core/parallel.h"

#if WHITTED_HAVE_MPI
#include <mpi.h>
#endif

namespace whitted {

size_t tile_message_bytes(const PixelWindow& tile, const AovSet& a) {
    const size_t per_pixel = sizeof(Color) + (a.depth ? sizeof(float) : 0) + (a.normal ? sizeof(Vec3f) : 0) +
                             (a.albedo ? sizeof(Color) : 0) + (a.prim_id ? sizeof(uint32_t) : 0) +
                             (a.inst_id ? sizeof(uint32_t) : 0) + (a.aa_samples ? sizeof(float) : 0);
    return sizeof(uint32_t) + per_pixel * size_t(tile.width()) * size_t(tile.height());
}

std::optional<std::string> MpiSession::agree_setup(const std::string& error) const {
    if (all(error.empty())) return std::nullopt;
    const bool root_failed = from_root(rank() == 0 && !error.empty());
    if (!error.empty() && rank() == 0) return error;
    if (!error.empty() && !root_failed) return fmt::format("rank {}: {}", rank(), error);
    if (rank() == 0) return std::string("set-up failed on other ranks");
    return std::string();
}

bool launched_by_mpi() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "MPI_LOCALNRANKS"})
        if (std::getenv(v)) return true;
    return false;
}

#if !WHITTED_HAVE_MPI

struct MpiSession::Lifetime {};
bool mpi_available() { return false; }
MpiSession::MpiSession() { throw Error("this whitted was built without MPI"); }
MpiSession::~MpiSession() = default;
int MpiSession::rank() const { return 0; }
int MpiSession::size() const { return 1; }
bool MpiSession::all(bool ok) const { return ok; }
bool MpiSession::from_root(bool value) const { return value; }
void MpiSession::abort(int code) const { std::exit(code); }
void MpiSession::finish() {}
void MpiSession::ready() const {}
MpiTileServer::MpiTileServer(const MpiSession& mpi, const Renderer& renderer) : m_mpi(mpi), m_renderer(renderer) {}
void MpiTileServer::serve(const TakeTiles&, const TileDone&, RenderStats&, const std::atomic<bool>*) {}
int MpiTileServer::workers() const { return 0; }
RenderStats serve_mpi_worker(const MpiSession&, const Renderer&) { return {}; }

#else

namespace {

/// A batch's most of the estimated work left, times the number of ranks.
constexpr double kBatchShare = 1.0 / 16.0;

enum Tag : int { kRequest = 1, kAssign = 2, kResult = 3, kStats = 4 };

// A worker's counters travel as RenderStats' raw bytes: the ranks run the same build.
static_assert(std::is_trivially_copyable_v<RenderStats>);

template <typename T>
uint8_t* put(uint8_t* p, const std::vector<T>& v) {
    if (!v.empty()) std::memcpy(p, v.data(), v.size() * sizeof(T));
    return p + v.size() * sizeof(T);
}

template <typename T>
const uint8_t* take(const uint8_t* p, std::vector<T>& v) {
    if (!v.empty()) std::memcpy(v.data(), p, v.size() * sizeof(T));
    return p + v.size() * sizeof(T);
}

/// A finished tile as one message: its index, then every buffer of its film.
std::vector<uint8_t> pack(uint32_t tile, const Film& f) {
    std::vector<uint8_t> out(tile_message_bytes(f.window, f.aovs));
    uint8_t* p = out.data();
    std::memcpy(p, &tile, sizeof(tile));
    p += sizeof(tile);
    p = put(p, f.beauty);
    p = put(p, f.depth);
    p = put(p, f.normal);
    p = put(p, f.albedo);
    p = put(p, f.prim_id);
    p = put(p, f.inst_id);
    put(p, f.aa_samples);
    return out;
}

/// The film of `bytes` (pack()'s layout) for `renderer`'s tile; throws when the size is not its.
std::pair<size_t, Film> unpack(const std::vector<uint8_t>& bytes, const Renderer& renderer,
                               const std::vector<TileRect>& tiles, int source) {
    uint32_t tile = 0;
    if (bytes.size() < sizeof(tile)) throw Error(fmt::format("MPI: a broken tile message from rank {}", source));
    std::memcpy(&tile, bytes.data(), sizeof(tile));
    if (tile >= tiles.size()) throw Error(fmt::format("MPI: rank {} sent tile {} of {}", source, tile, tiles.size()));
    const TileRect& t = tiles[tile];
    const ImageSize size = renderer.image_size();
    Film f(size.width, size.height, t, renderer.settings().aovs);
    const size_t expected = tile_message_bytes(f.window, f.aovs);
    if (bytes.size() != expected)
        throw Error(fmt::format("MPI: rank {} sent {} bytes for tile {}, expected {}", source, bytes.size(), tile, expected));
    const uint8_t* p = bytes.data() + sizeof(tile);
    p = take(p, f.beauty);
    p = take(p, f.depth);
    p = take(p, f.normal);
    p = take(p, f.albedo);
    p = take(p, f.prim_id);
    p = take(p, f.inst_id);
    take(p, f.aa_samples);
    return {tile, std::move(f)};
}

}  // namespace

bool mpi_available() { return true; }

/// MPI's state, owned by the thread that starts and ends it (MPI_Finalize belongs on the thread
/// that called MPI_Init_thread).
struct MpiSession::Lifetime {
    std::thread thread;
    std::mutex mutex;
    std::condition_variable changed;
    bool up = false;         // MPI_Init_thread has returned
    bool finishing = false;  // finish(): MPI_Finalize may run
    std::string error;       // why MPI cannot be used, once up
    int rank = -1, size = -1;
    int launcher_rank = -1, launcher_size = -1;  // from the environment, when it says
};

namespace {

/// The launcher's word for this process's rank and the job's size (Open MPI, then MPICH's PMI);
/// {-1, -1} when it does not say.
std::pair<int, int> launcher_rank() {
    for (const auto& [rank, size] : {std::pair{"OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE"},
                                     std::pair{"PMI_RANK", "PMI_SIZE"}}) {
        const char* r = std::getenv(rank);
        const char* n = std::getenv(size);
        if (r && n && *r && *n) return {std::atoi(r), std::atoi(n)};
    }
    return {-1, -1};
}

}  // namespace

MpiSession::MpiSession() : m(std::make_unique<Lifetime>()) {
    std::tie(m->launcher_rank, m->launcher_size) = launcher_rank();
    m->thread = std::thread([l = m.get()] {
        int provided = 0, rank = 0, size = 1;
        MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
        MPI_Comm_rank(MPI_COMM_WORLD, &rank);
        MPI_Comm_size(MPI_COMM_WORLD, &size);
        std::unique_lock<std::mutex> lock(l->mutex);
        if (provided < MPI_THREAD_SERIALIZED)
            l->error = "MPI: this MPI library does not support MPI_THREAD_SERIALIZED";
        else if (l->launcher_rank >= 0 && (l->launcher_rank != rank || l->launcher_size != size))
            l->error = fmt::format("MPI: the launcher says rank {} of {}, MPI says rank {} of {}", l->launcher_rank,
                                   l->launcher_size, rank, size);
        l->rank = rank;
        l->size = size;
        l->up = true;
        l->changed.notify_all();
        l->changed.wait(lock, [l] { return l->finishing; });
        lock.unlock();
        MPI_Finalize();
    });
}

MpiSession::~MpiSession() {
    finish();
    m->thread.join();
}

void MpiSession::ready() const {
    std::unique_lock<std::mutex> lock(m->mutex);
    RT_CHECK(!m->finishing);
    m->changed.wait(lock, [this] { return m->up; });
    if (!m->error.empty()) throw Error(m->error);
}

int MpiSession::rank() const {
    if (m->launcher_rank >= 0) return m->launcher_rank;
    ready();
    return m->rank;
}

int MpiSession::size() const {
    if (m->launcher_size >= 0) return m->launcher_size;
    ready();
    return m->size;
}

void MpiSession::finish() {
    const std::lock_guard<std::mutex> lock(m->mutex);
    m->finishing = true;
    m->changed.notify_all();
}

bool MpiSession::all(bool ok) const {
    ready();
    int mine = ok ? 1 : 0, every = 0;
    MPI_Allreduce(&mine, &every, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return every == 1;
}

bool MpiSession::from_root(bool value) const {
    ready();
    int v = value ? 1 : 0;
    MPI_Bcast(&v, 1, MPI_INT, 0, MPI_COMM_WORLD);
    return v == 1;
}

void MpiSession::abort(int code) const {
    bool finishing = false;
    {
        const std::lock_guard<std::mutex> lock(m->mutex);
        finishing = m->finishing;
    }
    if (!finishing) {
        ready();
        MPI_Abort(MPI_COMM_WORLD, code);
    }
    std::exit(code);
}

MpiTileServer::MpiTileServer(const MpiSession& mpi, const Renderer& renderer) : m_mpi(mpi), m_renderer(renderer) {}

int MpiTileServer::workers() const {
    // Every rank runs with the same flags; `--threads 0` is taken as this host's count.
    return (m_mpi.size() - 1) * resolve_threads(m_renderer.settings().threads);
}

void MpiTileServer::serve(const TakeTiles& take, const TileDone& give, RenderStats& stats,
                          const std::atomic<bool>* stop) {
    using Clock = std::chrono::steady_clock;
    // The other ranks' set-up, agreed here rather than before the render (this rank's own set-up
    // succeeded, or it would not serve), so that this rank's tiles start while MPI and the other
    // ranks are still starting. The ranks that failed have said why.
    if (const std::optional<std::string> failed = m_mpi.agree_setup("")) throw MpiSetupFailed(*failed);
    const std::vector<TileRect> tiles = m_renderer.tiles();
    int working = m_mpi.size() - 1;  // ranks that have not sent their final counters
    auto last_message = Clock::now();
    // Tiles are received without blocking (matched probe, then MPI_Imrecv): a tile is larger than
    // the eager limit, so its bytes move only when the sender next enters MPI, and a blocking
    // receive would spin until then.
    struct Incoming {
        std::vector<uint8_t> bytes;
        MPI_Request request = MPI_REQUEST_NULL;
        int source = 0;
    };
    std::list<Incoming> incoming;
    while (working > 0 || !incoming.empty()) {
        bool progressed = false;
        for (auto it = incoming.begin(); it != incoming.end();) {
            int received = 0;
            MPI_Test(&it->request, &received, MPI_STATUS_IGNORE);
            if (!received) {
                ++it;
                continue;
            }
            auto [tile, film] = unpack(it->bytes, m_renderer, tiles, it->source);
            give(tile, std::move(film));
            it = incoming.erase(it);
            progressed = true;
        }
        int flag = 0;
        MPI_Message message;
        MPI_Status probe;
        MPI_Improbe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &message, &probe);
        if (!flag) {
            if (progressed) continue;
            // Interrupted (a signal, or the launcher ending the job for a dead rank): the tiles in
            // flight arrive within moments; ranks silent for half a second are not waited for.
            if (stop && stop->load() && Clock::now() - last_message > std::chrono::milliseconds(500)) {
                log_warning("MPI: {} rank(s) did not finish after the interrupt; their tiles stay missing", working);
                for (Incoming& in : incoming) MPI_Cancel(&in.request);
                return;
            }
            // Nothing yet: give the core to this rank's own tiles (the others ask for the next
            // tiles while half of their batch is left, so this wait does not stall them).
            std::this_thread::sleep_for(std::chrono::microseconds(500));
            continue;
        }
        last_message = Clock::now();
        int count = 0;
        MPI_Get_count(&probe, MPI_BYTE, &count);
        if (probe.MPI_TAG == kResult) {
            Incoming& in = incoming.emplace_back();
            in.bytes.resize(size_t(std::max(count, 0)));
            in.source = probe.MPI_SOURCE;
            MPI_Imrecv(in.bytes.data(), count, MPI_BYTE, &message, &in.request);
            continue;
        }
        std::vector<uint8_t> bytes(size_t(std::max(count, 0)));
        MPI_Mrecv(bytes.data(), count, MPI_BYTE, &message, MPI_STATUS_IGNORE);
        if (probe.MPI_TAG == kRequest) {
            int want = 0;
            if (bytes.size() == sizeof(want)) std::memcpy(&want, bytes.data(), sizeof(want));
            // Guided by the estimated work: a batch holds at most 1/(16 N) of the work left, so the
            // last tiles spread over every rank instead of waiting in a few queues (the factor chosen
            // with scripts/simulate_mpi.py, docs/measurements/distributed.md).
            std::vector<uint32_t> assigned;
            for (const size_t t : take(size_t(std::max(want, 1)), kBatchShare / double(m_mpi.size())))
                assigned.push_back(uint32_t(t));
            MPI_Send(assigned.data(), int(assigned.size()), MPI_UINT32_T, probe.MPI_SOURCE, kAssign, MPI_COMM_WORLD);
        } else if (probe.MPI_TAG == kStats) {
            RenderStats w;
            if (bytes.size() != sizeof(w)) throw Error(fmt::format("MPI: broken counters from rank {}", probe.MPI_SOURCE));
            std::memcpy(&w, bytes.data(), sizeof(w));
            stats.add(w);
            --working;
        } else {
            throw Error(fmt::format("MPI: unexpected message tag {} from rank {}", probe.MPI_TAG, probe.MPI_SOURCE));
        }
    }
}

RenderStats serve_mpi_worker(const MpiSession& mpi, const Renderer& renderer) {
    (void)mpi;
    // Tiles arrive a few at a time; the next batch is asked for while half of this one is left,
    // so that it is on its way while these render.
    const int want = std::max(8, 8 * resolve_threads(renderer.settings().threads));
    std::deque<uint32_t> queue;
    bool asked = false, finished = false;
    // Finished tiles go out without waiting: a tile is larger than the eager limit of shared
    // memory, so a blocking send would wait for rank 0 to post its receive.
    struct Outgoing {
        std::vector<uint8_t> bytes;
        MPI_Request request = MPI_REQUEST_NULL;
    };
    std::list<Outgoing> outgoing;
    auto reap = [&](bool wait) {
        for (auto it = outgoing.begin(); it != outgoing.end();) {
            int sent = 0;
            if (wait) {
                MPI_Wait(&it->request, MPI_STATUS_IGNORE);
                sent = 1;
            } else {
                MPI_Test(&it->request, &sent, MPI_STATUS_IGNORE);
            }
            it = sent ? outgoing.erase(it) : std::next(it);
        }
    };
    auto receive_assignment = [&](bool block) {
        int flag = 1;
        MPI_Status probe;
        if (block) MPI_Probe(0, kAssign, MPI_COMM_WORLD, &probe);
        else MPI_Iprobe(0, kAssign, MPI_COMM_WORLD, &flag, &probe);
        if (!flag) return;
        int count = 0;
        MPI_Get_count(&probe, MPI_UINT32_T, &count);
        std::vector<uint32_t> assigned(size_t(std::max(count, 0)));
        MPI_Recv(assigned.data(), count, MPI_UINT32_T, 0, kAssign, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        asked = false;
        if (assigned.empty()) finished = true;
        queue.insert(queue.end(), assigned.begin(), assigned.end());
    };
    // render_tiles calls these one at a time (MPI_THREAD_SERIALIZED), from its worker threads.
    auto next = [&]() -> std::optional<size_t> {
        reap(false);
        if (asked) receive_assignment(false);
        for (;;) {
            if (!finished && !asked && queue.size() <= size_t(want / 2)) {
                MPI_Send(&want, 1, MPI_INT, 0, kRequest, MPI_COMM_WORLD);
                asked = true;
            }
            if (!queue.empty()) {
                const uint32_t t = queue.front();
                queue.pop_front();
                return t;
            }
            if (finished) return std::nullopt;
            receive_assignment(true);
        }
    };
    auto done = [&](size_t tile, Film&& film) {
        Outgoing& o = outgoing.emplace_back();
        o.bytes = pack(uint32_t(tile), film);
        MPI_Isend(o.bytes.data(), int(o.bytes.size()), MPI_BYTE, 0, kResult, MPI_COMM_WORLD, &o.request);
    };
    RenderStats stats;
    renderer.render_tiles(next, done, &stats);
    // render_tiles runs one iteration per tile of the frame: when this rank got every tile, the
    // last iteration rendered one, and rank 0's closing (empty) answer is still to be read.
    while (!finished) receive_assignment(true);
    RT_CHECK(queue.empty());
    reap(true);
    MPI_Send(&stats, int(sizeof(stats)), MPI_BYTE, 0, kStats, MPI_COMM_WORLD);
    return stats;
}

#endif

}  // namespace whitted
