#include "session/sequence.h"

#include <cerrno>
#include <cstdlib>

#include <fmt/format.h>

#include "core/error.h"
#include "importers/scene_loader.h"
#include "scene/scene.h"

namespace whitted {

namespace {

/// A whole non-negative decimal number, or -1.
long parse_frame(const std::string& s) {
    if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos || s.size() > 9) return -1;
    return std::strtol(s.c_str(), nullptr, 10);
}

}  // namespace

FrameRange parse_frame_range(const std::string& text, const std::string& flag) {
    const size_t dash = text.find('-');
    const long a = parse_frame(text.substr(0, dash));
    const long b = dash == std::string::npos ? a : parse_frame(text.substr(dash + 1));
    if (a < 0 || b < 0 || b < a)
        throw Error(fmt::format("{} {}: expected A-B, whole frame numbers with 0 <= A <= B", flag, text));
    FrameRange r;
    r.first = int(a);
    r.last = int(b);
    return r;
}

std::string frame_path(const std::string& pattern, int frame) {
    const size_t end = pattern.find_last_of('#');
    if (end == std::string::npos)
        throw Error(fmt::format("--frames: the output name {} has no '#' for the frame number (e.g. out_####.exr)",
                                pattern));
    const size_t before = pattern.find_last_not_of('#', end);  // npos: the run starts the name
    const size_t begin = before == std::string::npos ? 0 : before + 1;
    const size_t width = end + 1 - begin;
    return pattern.substr(0, begin) + fmt::format("{:0{}d}", frame, width) + pattern.substr(end + 1);
}

Bounds3d sequence_bounds(Scene& scene, SceneAnimator& animator, const FrameRange& range) {
    Bounds3d all = scene.world_bounds();
    for (int k = range.first + 1; k <= range.last; ++k) {
        animator.pose(scene, frame_time(k, range.fps));
        all.extend(scene.world_bounds());
    }
    if (range.count() > 1) animator.pose(scene, frame_time(range.first, range.fps));
    return all;
}

}  // namespace whitted
