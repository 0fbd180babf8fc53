#include "renderer/session/mpi_frame.h"

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
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

/// What a worker reports at the end (raw bytes: the ranks run the same build).
struct WorkerStats {
    RayCounters rays;
    uint64_t nonfinite = 0, pixels = 0, subdivided = 0;
    int threads = 0;
};
static_assert(std::is_trivially_copyable_v<WorkerStats>);

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

/// Bytes of pack()'s message for a film.
size_t packed_size(const Film& f) {
    return sizeof(uint32_t) + f.beauty.size() * sizeof(Color) + f.depth.size() * sizeof(float) +
           f.normal.size() * sizeof(Vec3f) + f.albedo.size() * sizeof(Color) + f.prim_id.size() * sizeof(uint32_t) +
           f.inst_id.size() * sizeof(uint32_t) + f.aa_samples.size() * sizeof(float);
}

/// A finished tile as one message: its index, then every buffer of its film.
std::vector<uint8_t> pack(uint32_t tile, const Film& f) {
    std::vector<uint8_t> out(packed_size(f));
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
    Film f(size.width, size.height, PixelWindow{t.x0, t.y0, t.x1, t.y1}, renderer.settings().aovs);
    const size_t expected = packed_size(f);
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

std::vector<uint8_t> receive_bytes(const MPI_Status& probe) {
    int count = 0;
    MPI_Get_count(&probe, MPI_BYTE, &count);
    std::vector<uint8_t> bytes(size_t(std::max(count, 0)));
    MPI_Recv(bytes.data(), count, MPI_BYTE, probe.MPI_SOURCE, probe.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return bytes;
}

}  // namespace

bool mpi_available() { return true; }

MpiSession::MpiSession(int* argc, char*** argv) {
    int provided = 0;
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
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
    while (working > 0) {
        int flag = 0;
        MPI_Status probe;
        MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &probe);
        if (!flag) {  // nothing yet: give the core to this rank's own tiles
            // Interrupted (a signal, or the launcher ending the job for a dead rank): the tiles in
            // flight arrive within moments; ranks silent for half a second are not waited for.
            if (stop && stop->load() && Clock::now() - last_message > std::chrono::milliseconds(500)) {
                log_warning("MPI: {} rank(s) did not finish after the interrupt; their tiles stay missing", working);
                return;
            }
            std::this_thread::sleep_for(std::chrono::microseconds(200));
            continue;
        }
        last_message = Clock::now();
        const std::vector<uint8_t> bytes = receive_bytes(probe);
        if (probe.MPI_TAG == kRequest) {
            int want = 0;
            if (bytes.size() == sizeof(want)) std::memcpy(&want, bytes.data(), sizeof(want));
            std::vector<uint32_t> assigned;
            for (int i = 0; i < want; ++i) {
                const std::optional<size_t> t = take_tile();
                if (!t) break;
                assigned.push_back(uint32_t(*t));
            }
            MPI_Send(assigned.data(), int(assigned.size()), MPI_UINT32_T, probe.MPI_SOURCE, kAssign, MPI_COMM_WORLD);
        } else if (probe.MPI_TAG == kResult) {
            auto [tile, film] = unpack(bytes, m_renderer, tiles, probe.MPI_SOURCE);
            give(tile, std::move(film));
        } else if (probe.MPI_TAG == kStats) {
            WorkerStats w;
            if (bytes.size() != sizeof(w)) throw Error(fmt::format("MPI: broken counters from rank {}", probe.MPI_SOURCE));
            std::memcpy(&w, bytes.data(), sizeof(w));
            stats.rays += w.rays;
            stats.nonfinite_samples += w.nonfinite;
            stats.pixels += w.pixels;
            stats.pixels_subdivided += w.subdivided;
            stats.threads += w.threads;
            --working;
        } else {
            throw Error(fmt::format("MPI: unexpected message tag {} from rank {}", probe.MPI_TAG, probe.MPI_SOURCE));
        }
    }
}

RenderStats serve_mpi_worker(const MpiSession& mpi, const Renderer& renderer) {
    (void)mpi;
    // A few tiles per request, so that the next assignment arrives while these render.
    const int threads = renderer.settings().threads > 0 ? renderer.settings().threads
                                                         : int(std::thread::hardware_concurrency());
    const int want = std::max(2, 2 * threads);
    RenderStats stats;
    MPI_Send(&want, 1, MPI_INT, 0, kRequest, MPI_COMM_WORLD);
    for (;;) {
        MPI_Status probe;
        MPI_Probe(0, kAssign, MPI_COMM_WORLD, &probe);
        int count = 0;
        MPI_Get_count(&probe, MPI_UINT32_T, &count);
        std::vector<uint32_t> assigned(size_t(std::max(count, 0)));
        MPI_Recv(assigned.data(), count, MPI_UINT32_T, 0, kAssign, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (assigned.empty()) break;
        MPI_Send(&want, 1, MPI_INT, 0, kRequest, MPI_COMM_WORLD);  // the next batch, while this one renders
        size_t handed = 0;
        std::vector<std::vector<uint8_t>> results;
        renderer.render_tiles(
            [&]() -> std::optional<size_t> {
                return handed < assigned.size() ? std::optional<size_t>(assigned[handed++]) : std::nullopt;
            },
            [&](size_t tile, Film&& film) { results.push_back(pack(uint32_t(tile), film)); }, &stats);
        for (const std::vector<uint8_t>& r : results)
            MPI_Send(r.data(), int(r.size()), MPI_BYTE, 0, kResult, MPI_COMM_WORLD);
    }
    WorkerStats w;
    w.rays = stats.rays;
    w.nonfinite = stats.nonfinite_samples;
    w.pixels = stats.pixels;
    w.subdivided = stats.pixels_subdivided;
    w.threads = stats.threads;
    MPI_Send(&w, int(sizeof(w)), MPI_BYTE, 0, kStats, MPI_COMM_WORLD);
    return stats;
}

#endif

}  // namespace whitted
