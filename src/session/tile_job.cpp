#include "session/tile_job.h"

#include <algorithm>
#include <sstream>

#include <fmt/format.h>

#include "core/error.h"
#include "session/frame_render.h"

namespace whitted {

namespace {

constexpr const char* kJobKey = "whitted:tileJob";
constexpr const char* kFrameKey = "whitted:frameWindow";

std::string window_text(const PixelWindow& w) { return fmt::format("{},{},{},{}", w.x0, w.y0, w.x1, w.y1); }

struct Part {
    std::string path;
    TileJob job;
    Film film;
    std::map<std::string, std::string> meta;
};

}  // namespace

TileJob parse_tile_job(const std::string& text) {
    TileJob job;
    char slash = 0;
    std::istringstream in(text);
    if (!(in >> job.index >> slash >> job.count) || slash != '/' || !(in >> std::ws).eof() || job.count < 1 ||
        job.index < 1 || job.index > job.count)
        throw Error(fmt::format("--tile-job: expected i/n with 1 <= i <= n, got '{}'", text));
    return job;
}

PixelWindow tile_job_window(const PixelWindow& frame, const TileJob& job) {
    const int rows = frame.height(), n = job.count;
    if (rows < n) throw Error(fmt::format("--tile-job {}/{}: the frame has only {} rows", job.index, n, rows));
    const int base = rows / n, extra = rows % n, i = job.index - 1;
    const int y0 = frame.y0 + i * base + std::min(i, extra);
    return {frame.x0, y0, frame.x1, y0 + base + (i < extra ? 1 : 0)};
}

std::map<std::string, std::string> tile_job_metadata(const TileJob& job, const PixelWindow& frame,
                                                     const SettingList& identity) {
    std::map<std::string, std::string> meta = identity_metadata(identity);
    meta[kJobKey] = fmt::format("{}/{}", job.index, job.count);
    meta[kFrameKey] = window_text(frame);
    return meta;
}

Film merge_parts(const std::vector<std::string>& paths, std::map<std::string, std::string>* metadata,
                 bool* half_parts) {
    const std::string setting_prefix = setting_key("");
    if (paths.empty()) throw Error("merge: no parts given");
    std::vector<Part> parts;
    bool all_half = true;
    for (const std::string& path : paths) {
        Part p;
        p.path = path;
        PixelType beauty = PixelType::Float;
        p.film = read_film(path, &p.meta, &beauty);
        all_half = all_half && beauty == PixelType::Half;
        const auto job = p.meta.find(kJobKey);
        if (job == p.meta.end() || !p.meta.count(kFrameKey))
            throw Error(fmt::format("{}: not a tile-job part (no {} metadata)", path, kJobKey));
        try {
            p.job = parse_tile_job(job->second);
        } catch (const Error&) {
            throw Error(fmt::format("{}: broken {} '{}'", path, kJobKey, job->second));
        }
        parts.push_back(std::move(p));
    }
    const Part& first = parts.front();
    // Every part of one frame and one set of settings.
    for (const Part& p : parts) {
        if (p.job.count != first.job.count)
            throw Error(fmt::format("{}: part {}/{} of another job than {} ({}/{})", p.path, p.job.index, p.job.count,
                                    first.path, first.job.index, first.job.count));
        for (const auto& [key, value] : first.meta) {
            if (key.rfind(setting_prefix, 0) != 0 && key != kFrameKey) continue;
            const auto it = p.meta.find(key);
            const std::string other = it == p.meta.end() ? "(not recorded)" : it->second;
            if (other != value) {
                const std::string name = key == kFrameKey ? "frame" : key.substr(setting_prefix.size());
                throw Error(fmt::format("{}: made with {} = {}, but {} with {} = {}", p.path, name, other, first.path,
                                        name, value));
            }
        }
        if (p.film.full_width != first.film.full_width || p.film.full_height != first.film.full_height)
            throw Error(fmt::format("{}: a {}x{} image, but {} is {}x{}", p.path, p.film.full_width, p.film.full_height,
                                    first.path, first.film.full_width, first.film.full_height));
    }
    // Each job once, each at its band.
    PixelWindow frame;
    {
        const std::string& f = first.meta.at(kFrameKey);
        char c1 = 0, c2 = 0, c3 = 0;
        std::istringstream in(f);
        if (!(in >> frame.x0 >> c1 >> frame.y0 >> c2 >> frame.x1 >> c3 >> frame.y1) || frame.width() <= 0 ||
            frame.height() <= 0)
            throw Error(fmt::format("{}: broken {} '{}'", first.path, kFrameKey, f));
    }
    std::vector<const Part*> by_job(size_t(first.job.count), nullptr);
    for (const Part& p : parts) {
        const Part*& slot = by_job[size_t(p.job.index - 1)];
        if (slot)
            throw Error(fmt::format("{} and {} are both part {}/{}: they overlap", slot->path, p.path, p.job.index,
                                    p.job.count));
        slot = &p;
        const PixelWindow want = tile_job_window(frame, p.job);
        if (!(p.film.window == want))
            throw Error(fmt::format("{}: part {}/{} holds rows {}-{}, columns {}-{}; the job's band is rows {}-{}, "
                                    "columns {}-{}",
                                    p.path, p.job.index, p.job.count, p.film.window.y0, p.film.window.y1 - 1,
                                    p.film.window.x0, p.film.window.x1 - 1, want.y0, want.y1 - 1, want.x0, want.x1 - 1));
    }
    for (int i = 1; i <= first.job.count; ++i)
        if (!by_job[size_t(i - 1)]) {
            const PixelWindow w = tile_job_window(frame, TileJob{i, first.job.count});
            throw Error(fmt::format("merge: part {}/{} (rows {}-{}) is missing", i, first.job.count, w.y0, w.y1 - 1));
        }
    Film film(first.film.full_width, first.film.full_height, frame, first.film.aovs);
    for (const Part& p : parts) {
        if (!film.can_paste(p.film))
            throw Error(fmt::format("{}: other output channels (AOVs) than {}", p.path, first.path));
        film.paste(p.film);
    }
    if (metadata) {
        metadata->clear();
        for (const auto& [key, value] : first.meta)
            if (key.rfind(setting_prefix, 0) == 0) (*metadata)[key] = value;
    }
    if (half_parts) *half_parts = all_half;
    return film;
}

}  // namespace whitted
