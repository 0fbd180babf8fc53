// One frame over MPI ranks, image-parallel (docs/distributed.md): every rank loads the scene and
// builds its own accelerator; rank 0 hands out tiles on request (a work queue, in frame order, a
// few per rank at a time so that the next ones are on their way while these render), renders
// tiles too, assembles the film, and alone writes the output, the checkpoint and the progress bar.
// Each tile is Renderer::render_tiles', so the image is bit-identical to a single process's for
// any number of ranks, threads and tile size.
#pragma once

#include <atomic>
#include <string>

#include "renderer/integrator/render.h"
#include "renderer/session/frame_render.h"

namespace whitted {

/// True when an MPI launcher started this process (mpirun, mpiexec, srun: their environment
/// variables), found without initialising MPI: a plain run never touches it.
bool launched_by_mpi();

/// Bytes of a finished tile's message to rank 0: its index, then every buffer of its film.
size_t tile_message_bytes(const PixelWindow& tile, const AovSet& aovs);

/// Whether this build has MPI (Open MPI from Debian; CMake's find_package(MPI)).
bool mpi_available();

/// MPI for the life of the object (MPI_Init_thread, serialized: any thread may call MPI, never
/// two at once; MPI_Finalize at the end). One per process.
class MpiSession {
public:
    /// Throws whitted::Error when the build has no MPI.
    MpiSession(int* argc, char*** argv);
    ~MpiSession();
    MpiSession(const MpiSession&) = delete;
    MpiSession& operator=(const MpiSession&) = delete;
    int rank() const { return m_rank; }
    int size() const { return m_size; }
    /// Collective: true when `ok` is true on every rank.
    bool all(bool ok) const;
    /// Collective: rank 0's `value`, on every rank.
    bool from_root(bool value) const;
    /// Ends every rank of the job with `code` (MPI_Abort).
    [[noreturn]] void abort(int code) const;

private:
    int m_rank = 0, m_size = 1;
};

/// The rank-0 side: tiles for the other ranks, for render_frame(renderer, options, &helpers).
class MpiTileServer : public TileHelpers {
public:
    MpiTileServer(const MpiSession& mpi, const Renderer& renderer);
    void serve(const NextTile& take, const TileDone& give, RenderStats& stats, const std::atomic<bool>* stop) override;

private:
    const MpiSession& m_mpi;
    const Renderer& m_renderer;
};

/// The other ranks: render the tiles rank 0 hands out and send them back, until it says there are
/// no more. Returns this rank's counters.
RenderStats serve_mpi_worker(const MpiSession& mpi, const Renderer& renderer);

}  // namespace whitted
