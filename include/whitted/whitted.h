// whitted as a library: the stable surface, in the order data flows (docs/library.md).
//
//   #include <whitted/whitted.h>            // find_package(whitted CONFIG REQUIRED)
//                                           // target_link_libraries(app PRIVATE whitted::whitted)
//   whitted::Scene scene = whitted::load_scene("scene.glb");
//   whitted::RenderSettings rs = whitted::command_line_render_settings();  // or RenderSettings{}
//   rs.width = 640;
//   whitted::Renderer renderer(scene, rs);  // builds the accelerator
//   whitted::Film film = renderer.render();
//   whitted::write_image(film, "out.png", {});
//
// Every function reports bad input by throwing whitted::Error (one line naming the file and the
// problem; Error::location() holds the file and JSON pointer where one applies).
//
// 1. Scenes: load_scene / import_gltf / import_gltf_memory and ImportOptions (files, the
//    environment), describe_scene (what `whitted info` prints), the plain Scene data.
// 2. Render settings: RenderSettings (size, camera, crop, anti-aliasing, integrator, AOVs,
//    exposure, accelerator, threads), apply_scene_settings (a scene file's settings under the
//    caller's), parse_color / parse_aovs / parse_crop.
// 3. Rendering into a Film: Renderer (render, render_tiles, tiles, tile_costs), RenderStats;
//    render_frame for interruptible renders with checkpoints and resume.
// 4. Output: write_image (EXR scene-linear with AOVs; PNG/JPEG/TIFF through OCIO), DisplayTransform,
//    read_film.
// 5. Accelerators and ray queries: create_accelerator(name, scene, filter) with
//    accelerator_names(), Accelerator::intersect / transmittance; a Renderer's accelerator() and
//    view() (the SurfaceFilter of its materials) answer for its scene.
//
// The headers these include are installed with them and may be used, but only what is named
// here is kept stable between minor versions.
#pragma once

#include "importers/scene_loader.h"
#include "importers/scene_report.h"
#include "accel/accelerator.h"
#include "accel/factory/create_accelerator.h"
#include "core/error.h"
#include "film/film.h"
#include "integrator/render.h"
#include "integrator/render_settings.h"
#include "integrator/scene_view.h"
#include "output/image_output.h"
#include "scene/scene.h"
#include "session/frame_render.h"

namespace whitted {

/// The library's version, "major.minor.patch" (as whittedConfigVersion.cmake).
const char* version();

}  // namespace whitted
