#include "session/frame_render.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include <fmt/format.h>

#include "core/error.h"
#include "core/log.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "output/image_output.h"

namespace whitted {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr const char* kCheckpointKey = "whitted:checkpoint";
constexpr const char* kTilesKey = "whitted:checkpointTiles";

/// The done flags as a string of '0' and '1' (one per tile, readable in `oiiotool --info -v`).
std::string encode_done(const std::vector<uint8_t>& done) {
    std::string s(done.size(), '0');
    for (size_t i = 0; i < done.size(); ++i) s[i] = done[i] ? '1' : '0';
    return s;
}

void write_checkpoint(const std::string& path, const FrameResult& frame, const SettingList& identity) {
    OutputSettings os;
    os.exr_half = false;  // exact: the resumed frame must be bit-identical
    os.metadata.insert_or_assign(kCheckpointKey, std::string(1, '1'));
    os.metadata[kTilesKey] = encode_done(frame.done);
    os.metadata.merge(identity_metadata(identity));
    write_image(frame.film, path, os);
}

/// Takes a checkpoint's finished tiles into `frame` after checking that it belongs to this render.
void resume_from(const std::string& path, const SettingList& identity, FrameResult& frame) {
    if (!fs::exists(path)) throw Error(fmt::format("--resume: no checkpoint {}", path));
    std::map<std::string, std::string> meta;
    const Film saved = read_film(path, &meta);
    if (!meta.count(kCheckpointKey)) throw Error(fmt::format("{}: not a whitted checkpoint", path));
    for (const auto& [key, value] : identity) {
        const auto it = meta.find(setting_key(key));
        const std::string was = it == meta.end() ? "(not recorded)" : it->second;
        if (was != value)
            throw Error(fmt::format("{}: made with {} = {}, this render has {} = {} (render without --resume to "
                                    "start again)",
                                    path, key, was, key, value));
    }
    const auto tiles = meta.find(kTilesKey);
    if (tiles == meta.end() || tiles->second.size() != frame.tiles.size() || !(saved.window == frame.film.window) ||
        !frame.film.can_paste(saved))
        throw Error(fmt::format("{}: its tiles do not match this render's {} tiles of window {},{},{},{}", path,
                                frame.tiles.size(), frame.film.window.x0, frame.film.window.y0, frame.film.window.x1,
                                frame.film.window.y1));
    frame.film = saved;
    for (size_t i = 0; i < frame.tiles.size(); ++i) {
        const char c = tiles->second[i];
        if (c != '0' && c != '1') throw Error(fmt::format("{}: broken tile list", path));
        frame.done[i] = c == '1';
        frame.resumed += frame.done[i];
    }
}

}  // namespace

std::vector<size_t> FrameResult::missing() const {
    std::vector<size_t> out;
    for (size_t i = 0; i < done.size(); ++i)
        if (!done[i]) out.push_back(i);
    return out;
}

std::string describe_tiles(const std::vector<TileRect>& tiles, const std::vector<size_t>& which) {
    std::string s;
    for (const size_t i : which) {
        const TileRect& t = tiles[i];
        s += fmt::format("{}{},{},{},{}", s.empty() ? "" : " ", t.x0, t.y0, t.x1, t.y1);
    }
    return s;
}

std::string setting_key(const std::string& name) {
    std::string key = "whitted:setting:";  // appended: `prefix + name` trips a -Wrestrict false positive
    key += name;
    return key;
}

std::map<std::string, std::string> identity_metadata(const SettingList& identity) {
    std::map<std::string, std::string> meta;
    for (const auto& [name, value] : identity) meta[setting_key(name)] = value;
    return meta;
}

std::string checkpoint_path_for(const std::string& output) { return output + ".checkpoint.exr"; }

std::string file_identity(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(fmt::format("{}: cannot read", path));
    uint64_t hash = 0xcbf29ce484222325ull, size = 0;
    char buffer[1 << 16];
    while (in) {
        in.read(buffer, sizeof(buffer));
        const std::streamsize n = in.gcount();
        for (std::streamsize i = 0; i < n; ++i) hash = (hash ^ uint8_t(buffer[i])) * 0x100000001b3ull;
        size += uint64_t(n);
    }
    return fmt::format("{} bytes, fnv1a64 {:016x}", size, hash);
}

FrameResult render_frame(const Renderer& renderer, const FrameOptions& options, TileHelpers* helpers) {
    FrameResult frame;
    frame.tiles = renderer.tiles();
    frame.done.assign(frame.tiles.size(), 0);
    frame.tile_seconds.assign(frame.tiles.size(), 0.0);
    std::vector<Clock::time_point> handed_at(frame.tiles.size());
    const ImageSize size = renderer.image_size();
    frame.film = Film(size.width, size.height, renderer.window(), renderer.settings().aovs);
    if (options.resume) {
        resume_from(options.checkpoint_path, options.identity, frame);
        log_info("resumed {} of {} tiles from {}", frame.resumed, frame.tiles.size(), options.checkpoint_path);
    }

    // The frame's state, shared by this process's workers and the helpers' server thread.
    std::mutex state;
    ProgressBar progress(frame.tiles.size() - frame.resumed, options.progress);
    // The tiles to render, in the order they are handed out, and their estimated work (1 each in
    // frame order).
    std::vector<size_t> order;
    for (size_t i = 0; i < frame.tiles.size(); ++i)
        if (!frame.done[i]) order.push_back(i);
    std::vector<double> work(frame.tiles.size(), 1.0);
    const int workers = resolve_threads(renderer.settings().threads) + (helpers ? helpers->workers() : 0);
    const bool expensive_first = options.order == TileOrder::ExpensiveFirst ||
                                 (options.order == TileOrder::Auto && workers >= kExpensiveFirstWorkers);
    if (expensive_first && order.size() > 1) {
        const auto t_probe = Clock::now();
        frame.tile_cost = renderer.tile_costs();
        log_debug("tile order: costs of {} tiles estimated in {:.3f}s", frame.tile_cost.size(),
                  std::chrono::duration<double>(Clock::now() - t_probe).count());
        work = frame.tile_cost;
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return work[a] > work[b]; });
    }
    double work_left = 0.0;  // of the tiles not yet handed out
    for (const size_t t : order) work_left += work[t];
    size_t cursor = 0;
    auto last_save = Clock::now();
    std::atomic<bool> abandoned{false};  // the helpers failed: no new tiles
    // Under the lock.
    auto hand_out = [&]() -> std::optional<size_t> {
        if ((options.stop && options.stop->load()) || abandoned.load() || cursor == order.size()) return std::nullopt;
        const size_t tile = order[cursor++];
        work_left = cursor == order.size() ? 0.0 : std::max(0.0, work_left - work[tile]);
        handed_at[tile] = Clock::now();
        return tile;
    };
    auto next = [&]() -> std::optional<size_t> {
        const std::lock_guard<std::mutex> lock(state);
        return hand_out();
    };
    auto take = [&](size_t max_tiles, double share) {
        const std::lock_guard<std::mutex> lock(state);
        std::vector<size_t> batch;
        const double budget = share * work_left;
        double taken = 0.0;
        while (batch.size() < max_tiles && (batch.empty() || taken < budget)) {
            const std::optional<size_t> tile = hand_out();
            if (!tile) break;
            batch.push_back(*tile);
            taken += work[*tile];
        }
        return batch;
    };
    auto done = [&](size_t tile, Film&& film) {
        const std::lock_guard<std::mutex> lock(state);
        RT_CHECK(tile < frame.tiles.size() && frame.film.can_paste(film));
        frame.film.paste(film);
        frame.done[tile] = 1;
        frame.tile_seconds[tile] = std::chrono::duration<double>(Clock::now() - handed_at[tile]).count();
        progress.advance();
        if (options.checkpoint_seconds > 0 && !options.checkpoint_path.empty() &&
            std::chrono::duration<double>(Clock::now() - last_save).count() >= options.checkpoint_seconds) {
            write_checkpoint(options.checkpoint_path, frame, options.identity);
            last_save = Clock::now();
        }
    };
    if (!helpers) {
        renderer.render_tiles(next, done, &frame.stats);
    } else {
        std::exception_ptr local_error;
        RenderStats local;
        std::thread own([&] {
            try {
                renderer.render_tiles(next, done, &local);
            } catch (...) {
                local_error = std::current_exception();
            }
        });
        RenderStats remote;
        try {
            helpers->serve(take, done, remote, options.stop);
        } catch (...) {
            abandoned.store(true);
            own.join();
            throw;
        }
        own.join();
        if (local_error) std::rethrow_exception(local_error);
        const double share = double(local.pixels) / double(std::max<uint64_t>(local.pixels + remote.pixels, 1));
        log_info("tiles: {:.1f}% of the pixels rendered by this process, {:.1f}% by the helpers", 100.0 * share,
                 100.0 * (1.0 - share));
        frame.stats = local;
        frame.stats.add(remote);
    }
    progress.finish();

    if (!frame.missing().empty() && !options.checkpoint_path.empty())
        write_checkpoint(options.checkpoint_path, frame, options.identity);
    return frame;
}

}  // namespace whitted
