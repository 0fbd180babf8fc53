// SIGINT/SIGTERM during `whitted render` (docs/distributed.md, "Interruption and resume"): while
// tiles render, the first signal stops handing out new ones; the tiles in flight finish and the
// image is written with what is done (missing tiles 0, listed in its metadata) plus a checkpoint
// for --resume, then the run exits with 128 + signal. Before rendering starts it ends the process
// at once; during a write, the write (atomic, through a temporary file) finishes first. A second
// signal exits at once in every case, removing the temporary file of an unfinished write and
// leaving earlier files as they were.
#pragma once

#include <atomic>

namespace whitted {
class MpiSession;
}

namespace whitted::cli {

/// The state the handlers and the render share.
struct InterruptState {
    std::atomic<int> signals{0};         ///< signals received
    std::atomic<int> last_signal{0};     ///< the last one's number
    std::atomic<bool> writing{false};    ///< an image file is being written
    std::atomic<bool> rendering{false};  ///< tiles are being rendered
    std::atomic<bool> stop{false};       ///< no new tile may start (FrameOptions::stop)
    /// Under MPI, once the ranks render together an error on one rank ends them all (MPI_Abort):
    /// the others would wait for it forever.
    std::atomic<bool> mpi_running{false};
    MpiSession* mpi = nullptr;           ///< the process's MPI session, if launched by mpirun
};

/// The process's one InterruptState.
InterruptState& interrupts();

/// Installs the handlers of SIGINT and SIGTERM (and SIGUSR1 under MPI, which mpirun passes on).
void install_interrupt_handlers();

/// A worker rank ignores the signals: rank 0 decides, the others finish the tiles they hold.
void ignore_interrupts();

}  // namespace whitted::cli
