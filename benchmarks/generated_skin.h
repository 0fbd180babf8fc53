// A generated skinned glTF for `whitted bench anim`: an open tube standing on +Y, skinned to a
// chain of joints along its axis and bent by a LINEAR rotation animation, at any size.
//
// The tube has `segments` vertices around each of `rings` rings (radius 0.5, height 8, no seam
// vertices: the last segment wraps to the first) and 2 x segments x (rings - 1) triangles, with
// POSITION, NORMAL, JOINTS_0 (unsigned short) and WEIGHTS_0 (float). Joint j is the j-th link of
// a chain whose bones each span an equal slice of the height; a vertex is bound to the 4 joints
// nearest its height with uniform cubic B-spline weights (normalised at the ends of the chain).
// Each joint has one rotation channel (LINEAR, `keys` keys over `duration` seconds): an angle of
// 0.25 rad x sin(2 pi t / duration + 0.7 j) about a horizontal axis that turns by 0.5 rad from
// one joint to the next, so the tube sways and twists and every vertex moves in every frame.
// Everything is a function of the spec: the same spec writes the same bytes.
#pragma once

#include <cstddef>
#include <filesystem>

namespace whitted::app {

struct GeneratedSkinSpec {
    size_t triangles = 1000000;  ///< about this many triangles (the grid is rounded: at least 6 segments by 3 rings)
    int joints = 12;             ///< joints in the chain, 4 to 1000 (4 weights per vertex, all distinct)
    double duration = 2.0;       ///< seconds the animation lasts (its last key)
    int keys = 25;               ///< keys per rotation channel, evenly spaced over the duration (>= 2)
};

/// What write_generated_skin wrote.
struct GeneratedSkin {
    size_t vertices = 0;   ///< segments x rings
    size_t triangles = 0;  ///< 2 x segments x (rings - 1)
    int segments = 0;      ///< vertices around a ring
    int rings = 0;         ///< rings along the height
    size_t bytes = 0;      ///< size of the file
};

/// Writes the tube of `spec` as a binary glTF (.glb) to `path`, with one material, no camera and
/// no light; throws whitted::Error when the spec is out of range or the file cannot be written.
GeneratedSkin write_generated_skin(const std::filesystem::path& path, const GeneratedSkinSpec& spec);

}  // namespace whitted::app
