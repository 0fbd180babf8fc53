// An image sequence of an animated (or turning) scene: frames A..B at N frames per second, frame k
// at exactly time k / N, each written to the output name with its run of '#' replaced by the frame
// number (Blender's and pbrt's convention: out_####.exr -> out_0000.exr, ...). docs/cli.md.
#pragma once

#include <string>

#include "core/vecmath.h"

namespace whitted {

struct Scene;
class SceneAnimator;

/// Frames `first`..`last` (inclusive) at `fps` frames per second.
struct FrameRange {
    int first = 0;
    int last = 0;
    double fps = 24.0;
    int count() const { return last - first + 1; }
};

/// Parses "A-B" (0 <= A <= B) or "A" (one frame); throws whitted::Error naming `flag` when malformed.
FrameRange parse_frame_range(const std::string& text, const std::string& flag = "--frames");

/// Frame `frame`'s time in seconds: frame / fps, the same double `--time` parses from its decimal.
inline double frame_time(int frame, double fps) { return double(frame) / fps; }

/// The union of the scene's world bounds at every frame of `range`, posing `scene` with `animator`
/// (load_animated_scene); afterwards the scene is posed at the first frame again. What the default
/// camera of a sequence frames, fixed over the frames.
Bounds3d sequence_bounds(Scene& scene, SceneAnimator& animator, const FrameRange& range);

/// `pattern` with its (last) run of '#' replaced by `frame`, zero-padded to the run's length (wider
/// numbers are written whole). Throws whitted::Error when `pattern` has no '#'.
std::string frame_path(const std::string& pattern, int frame);

}  // namespace whitted
