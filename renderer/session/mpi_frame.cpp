#include "renderer/session/mpi_frame.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <deque>
#include <iterator>
#include <list>
#include <thread>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "renderer/core/error.h"
#include "renderer/core/log.h"

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

bool launched_by_mpi() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "MPI_LOCALNRANKS"})
        if (std::getenv(v)) return true;
    return false;
}

#if !WHITTED_HAVE_MPI

bool mpi_available() { return false; }
MpiSession::MpiSession(int*, char***) { throw Error("this whitted was built without MPI"); }
MpiSession::~MpiSession() = default;
bool MpiSession::all(bool ok) const { return ok; }
bool MpiSession::from_root(bool value) const { return value; }
void MpiSession::abort(int code) const { std::exit(code); }
MpiTileServer::MpiTileServer(const MpiSession& mpi, const Renderer& renderer) : m_mpi(mpi), m_renderer(renderer) {}
void MpiTileServer::serve(const NextTile&, const TileDone&, RenderStats&, const std::atomic<bool>*) {}
RenderStats serve_mpi_worker(const MpiSession&, const Renderer&) { return {}; }

#else

namespace {

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

MpiSession::MpiSession(int* argc, char*** argv) {
    int provided = 0;
    MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided);
    if (provided < MPI_THREAD_SERIALIZED) {
        MPI_Finalize();
        throw Error("MPI: this MPI library does not support MPI_THREAD_SERIALIZED");
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &m_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &m_size);
}

MpiSession::~MpiSession() { MPI_Finalize(); }

bool MpiSession::all(bool ok) const {
    int mine = ok ? 1 : 0, every = 0;
    MPI_Allreduce(&mine, &every, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return every == 1;
}

bool MpiSession::from_root(bool value) const {
    int v = value ? 1 : 0;
    MPI_Bcast(&v, 1, MPI_INT, 0, MPI_COMM_WORLD);
    return v == 1;
}

void MpiSession::abort(int code) const {
    MPI_Abort(MPI_COMM_WORLD, code);
    std::exit(code);
}

MpiTileServer::MpiTileServer(const MpiSession& mpi, const Renderer& renderer) : m_mpi(mpi), m_renderer(renderer) {}

void MpiTileServer::serve(const NextTile& take_tile, const TileDone& give, RenderStats& stats,
                          const std::atomic<bool>* stop) {
    using Clock = std::chrono::steady_clock;
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
    size_t handed_up_to = 0;  // tiles are handed out in frame order: those below are taken
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
            // Guided: batches shrink with the tiles left (at most what is left over twice the
            // ranks), so the last tiles spread over every rank instead of waiting in a few queues.
            const size_t left = tiles.size() - std::min(tiles.size(), handed_up_to);
            const int batch = int(std::clamp<size_t>(left / (2 * size_t(m_mpi.size())), 1, size_t(std::max(want, 1))));
            std::vector<uint32_t> assigned;
            for (int i = 0; i < batch; ++i) {
                const std::optional<size_t> t = take_tile();
                if (!t) break;
                assigned.push_back(uint32_t(*t));
                handed_up_to = std::max(handed_up_to, *t + 1);
            }
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
    const int threads = renderer.settings().threads > 0 ? renderer.settings().threads
                                                         : int(std::thread::hardware_concurrency());
    const int want = std::max(8, 8 * threads);
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
