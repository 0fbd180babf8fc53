// A frame rendered tile by tile so that it can stop early and go on later: an interrupt stops
// handing out tiles and keeps the finished ones, a checkpoint file holds them (periodically and
// at the interrupt), and a resumed render takes them back and renders only the rest. The tiles
// are Renderer::render_tiles', so the finished frame is bit-identical to an uninterrupted one.
// docs/distributed.md.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "film/film.h"
#include "integrator/render.h"
#include "integrator/render_settings.h"

namespace whitted {

/// The order render_frame hands tiles out in.
enum class TileOrder {
    Auto,           ///< ExpensiveFirst from kExpensiveFirstWorkers workers on (threads of every process), else Frame
    Frame,          ///< row-major, as Renderer::tiles() numbers them
    ExpensiveFirst  ///< by Renderer::tile_costs(), the dearest first, so that the last tiles are cheap
};

/// TileOrder::Auto's threshold. Below it the order does not matter (the simulated render phase is
/// within 0.5 % of ideal either way at 2-4 workers, docs/measurements/distributed.md) and the
/// estimate would cost 0.5-4 % of the render; from 8 on, the dearest first lifts it (0.91 -> 1.00
/// for glass_mirror_room at 8).
constexpr int kExpensiveFirstWorkers = 8;

struct FrameOptions {
    SettingList identity;                     ///< what the pixels depend on (settings, scene, version); a
                                              ///< checkpoint records it and a resume must match it
    std::string checkpoint_path;              ///< empty: never write a checkpoint
    double checkpoint_seconds = 0.0;          ///< > 0: save the finished tiles at least this often
    bool resume = false;                      ///< start from checkpoint_path's finished tiles
    const std::atomic<bool>* stop = nullptr;  ///< once true, no new tile starts (set by a signal handler)
    bool progress = false;                    ///< progress bar over the tiles on stderr
    TileOrder order = TileOrder::Auto;
};

struct FrameResult {
    Film film;                   ///< the window; unfinished tiles are 0 (ids: none)
    RenderStats stats;           ///< of the tiles rendered now
    std::vector<TileRect> tiles; ///< Renderer::tiles()
    std::vector<uint8_t> done;   ///< per tile: finished (now or from the checkpoint)
    size_t resumed = 0;          ///< tiles taken from the checkpoint
    std::vector<double> tile_seconds;  ///< per tile: from handed out to done (0: not rendered now)
    std::vector<double> tile_cost;     ///< per tile: the estimate it was ordered by (empty: frame order)
    /// Indices of the unfinished tiles (empty when the frame is complete).
    std::vector<size_t> missing() const;
};

/// TileHelpers::serve: up to `max_tiles` of the next tiles in the frame's order for one helper,
/// fewer once the estimated work of those taken reaches `share` of the work not yet handed out
/// (guided: batches shrink as the frame nears its end; at least one tile); none once every tile is
/// handed out or the render stops.
using TakeTiles = std::function<std::vector<size_t>(size_t max_tiles, double share)>;

/// Other processes rendering tiles of the same frame (MPI ranks: mpi_frame.h). render_frame then
/// renders its own tiles on a second thread and calls serve() on its own: serve hands tiles out
/// with `take`, gives finished ones back with `give`, adds the helpers' counters to `stats` and
/// returns when every helper is done, or soon after `stop` is set when helpers have gone quiet (a
/// dead rank must not keep the finished tiles from being written).
class TileHelpers {
public:
    virtual ~TileHelpers() = default;
    virtual void serve(const TakeTiles& take, const TileDone& give, RenderStats& stats,
                       const std::atomic<bool>* stop) = 0;
    /// Worker threads the helpers have between them (for TileOrder::Auto).
    virtual int workers() const = 0;
};

/// Renders the frame's tiles in options.order, skipping those a resumed checkpoint holds. With
/// options.stop set it returns early (tiles in flight finish first); when tiles are then missing
/// and a checkpoint path is set, the checkpoint is written (the caller removes it once the finished
/// frame is safely written). Throws whitted::Error naming the checkpoint when a resume finds none, a broken one,
/// or one made otherwise (the first setting that differs).
FrameResult render_frame(const Renderer& renderer, const FrameOptions& options, TileHelpers* helpers = nullptr);

/// The tiles `which` as text, "x0,y0,x1,y1" each, space-separated (the metadata of a partial image).
std::string describe_tiles(const std::vector<TileRect>& tiles, const std::vector<size_t>& which);

/// The metadata key a checkpoint or a tile-job part records setting `name` under:
/// "whitted:setting:<name>".
std::string setting_key(const std::string& name);
/// `identity` as metadata (setting_key of each name).
std::map<std::string, std::string> identity_metadata(const SettingList& identity);

/// Default checkpoint path beside an output image: "<output>.checkpoint.exr".
std::string checkpoint_path_for(const std::string& output);

/// A file's identity for FrameOptions::identity: its size and a 64-bit FNV-1a hash of its bytes.
/// Throws whitted::Error naming the file when it cannot be read.
std::string file_identity(const std::string& path);

}  // namespace whitted
