// Geometry the scene file generates: boxes, rectangles, inline meshes (private to importers/).
#pragma once

#include "scene/scene.h"

namespace whitted {

/// Axis-aligned box [lo, hi]: 24 vertices (4 per face), 12 triangles wound counter-clockwise
/// seen from outside, flat outward normals, UVs 0..1 on every face (image upright seen from
/// outside, +Y up on the side faces).
Mesh make_box_mesh(const Vec3d& lo, const Vec3d& hi);

/// Rectangle centred at `center` with unit `normal` and unit `u_axis` (perpendicular to it):
/// `width` along u_axis, `height` along cross(normal, u_axis). 4 vertices, 2 triangles facing
/// `normal`, UV (0, 0) at the corner -u/2 +v/2 so an image appears upright seen from the front.
Mesh make_rectangle_mesh(const Vec3d& center, const Vec3d& normal, const Vec3d& u_axis, double width, double height);

/// The default u_axis of a plane: the coordinate axis least aligned with `normal` (x, then y,
/// then z on ties) made perpendicular to it; unit length. `normal` must be unit.
Vec3d default_u_axis(const Vec3d& normal);

/// Swaps two indices of every triangle (for transforms with a negative determinant).
void flip_winding(Mesh& mesh);

}  // namespace whitted
