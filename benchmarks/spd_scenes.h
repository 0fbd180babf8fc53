// Scenes in the spirit of Eric Haines' Standard Procedural Databases (SPD, 1987), built in code
// from analytic cylinders, cones, discs and spheres (Scene::quadrics), with the same scenes'
// quadrics tessellated into meshes for comparison: what `whitted bench quadrics` renders.
//   - rings: a pyramid of rings, each a closed polygon of cylinders with a sphere at every joint
//     (SPD "rings"), over a ground disc;
//   - tree: a branching tree of truncated cones with a sphere at every branch tip (SPD "tree"),
//     over a ground disc;
//   - balls: a sphereflake, nine spheres a third of the size on every sphere (SPD "balls");
//   - tetra: a Sierpinski tetrahedron of flat triangles (SPD "tetra");
//   - mount: a fractal mountain of flat triangles with four spheres above it, one of glass (SPD
//     "mount");
//   - gears: a grid of meshing gears, flat triangles (SPD "gears").
// (SPD's teapot is not made.)
// Classic materials (mirror-like, as the SPD's), three point lights and a camera.
#pragma once

#include <string>
#include <vector>

#include "scene/scene.h"

namespace whitted::app {

/// The names make_spd_scene() knows: rings, tree, balls, tetra, mount, gears.
const std::vector<std::string>& spd_scene_names();

/// The scene `name` at `size` (SPD's size factor: rings size + 1 levels; tree depth 4 + size;
/// balls size levels below the first sphere, 1 + 9 + ... + 9^size spheres; tetra 4^(size + 1)
/// tetrahedra; mount 4^(size + 3) triangles; gears (size + 1)^2 gears of 256 triangles). Throws
/// whitted::Error for another name.
Scene make_spd_scene(const std::string& name, int size);

/// The same scene with every cylinder and cone tessellated into `segments` side quads (smooth
/// side normals, flat caps) and every disc into a `segments`-gon, one mesh instance each (the
/// shape's object space, placed by its world_from_object).
Scene tessellate_quadrics(const Scene& scene, int segments);

}  // namespace whitted::app
