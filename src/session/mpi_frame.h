// One frame over MPI ranks, image-parallel (docs/distributed.md): every rank loads the scene and
// builds its own accelerator; rank 0 hands out tiles on request (a work queue, the expensive tiles
// first, a few per rank at a time so that the next ones are on their way while these render), renders
// tiles too, assembles the film, and alone writes the output, the checkpoint and the progress bar.
// Each tile is Renderer::render_tiles', so the image is bit-identical to a single process's for
// any number of ranks, threads and tile size.
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <string>

#include "core/error.h"
#include "integrator/render.h"
#include "session/frame_render.h"

namespace whitted {

/// True when an MPI launcher started this process (mpirun, mpiexec, srun: their environment
/// variables), found without initialising MPI: a plain run never touches it.
bool launched_by_mpi();

/// Bytes of a finished tile's message to rank 0: its index, then every buffer of its film.
size_t tile_message_bytes(const PixelWindow& tile, const AovSet& aovs);

/// Whether this build has MPI (Open MPI from Debian; CMake's find_package(MPI)).
bool mpi_available();

/// MPI for the life of the object, on a thread of its own: MPI_Init_thread (serialized: any thread
/// may call MPI, never two at once) starts at construction and runs while the process loads its
/// scene; MPI_Finalize runs on the same thread at finish() (or destruction) while the caller goes on
/// writing its output. Calls made before MPI is up wait for it. One per process.
class MpiSession {
public:
    /// Throws whitted::Error when the build has no MPI.
    MpiSession();
    ~MpiSession();
    MpiSession(const MpiSession&) = delete;
    MpiSession& operator=(const MpiSession&) = delete;
    /// From the launcher's environment where it says (Open MPI, MPICH, Slurm), else from MPI once
    /// it is up; checked against MPI's own once it is.
    int rank() const;
    int size() const;
    /// Collective: true when `ok` is true on every rank.
    bool all(bool ok) const;
    /// Collective: rank 0's `value`, on every rank.
    bool from_root(bool value) const;
    /// Collective: the ranks agree on their set-up, `error` being this rank's (empty: it
    /// succeeded). Nothing when every rank succeeded; else the one line this rank reports, empty
    /// when another rank reports it: rank 0's error, else each failed rank's as "rank N: ...",
    /// and on rank 0 "set-up failed on other ranks" when only others failed.
    std::optional<std::string> agree_setup(const std::string& error) const;
    /// Ends every rank of the job with `code` (MPI_Abort; after finish(), only this process).
    [[noreturn]] void abort(int code) const;
    /// No more MPI calls from this process: MPI_Finalize starts on MPI's thread, without waiting.
    void finish();

private:
    /// Waits until MPI_Init_thread has returned; throws its error.
    void ready() const;
    struct Lifetime;
    std::unique_ptr<Lifetime> m;
};

/// Thrown on rank 0 when other ranks' set-up failed (they have printed why): no rank is left to
/// abort, the job just ends.
struct MpiSetupFailed : Error {
    explicit MpiSetupFailed(const std::string& line) : Error(line) {}
};

/// The rank-0 side: tiles for the other ranks, for render_frame(renderer, options, &helpers).
class MpiTileServer : public TileHelpers {
public:
    MpiTileServer(const MpiSession& mpi, const Renderer& renderer);
    void serve(const TakeTiles& take, const TileDone& give, RenderStats& stats,
               const std::atomic<bool>* stop) override;
    int workers() const override;

private:
    const MpiSession& m_mpi;
    const Renderer& m_renderer;
};

/// The other ranks: render the tiles rank 0 hands out and send them back, until it says there are
/// no more. Returns this rank's counters.
RenderStats serve_mpi_worker(const MpiSession& mpi, const Renderer& renderer);

}  // namespace whitted
