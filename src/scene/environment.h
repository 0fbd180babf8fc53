// The environment: a lat-long (equirectangular) HDR image surrounding the scene at infinity, as
// plain data. What a ray that leaves the scene sees (Whitted 1980) and, through
// src/shading/environment_map.h, the light it casts. Axis convention and units: docs/environment.md.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <memory>
#include <string>
#include <vector>

#include "core/vecmath.h"

namespace whitted {

/// Number of extracted lights when the caller does not choose (ImportOptions::environment_lights,
/// --env-lights): the fewest of 0, 1, 4, 16, 64, 256 whose display image `whitted bench env` finds
/// within 1/255 (RMSE) of 1024 lights on every asset and map it renders (64: 1.43/255 off on
/// default.glb under courtyard). Each costs at most a shadow ray per shaded point (fewer where the
/// adaptive shadow test stops); the lights plus the ambient give the map's irradiance within 1.2 %
/// at the 6 axis normals of studio and courtyard (docs/measurements/environment.md).
constexpr int kDefaultEnvironmentLights = 256;

/// A decoded lat-long image: column u = (x + 0.5) / width runs once around +Y, row 0 is the +Y
/// pole side and the last row the -Y side (docs/environment.md, "Axis convention").
struct EnvironmentImage {
    std::string name;                 ///< bundled name ("studio") or the file name, for messages
    std::string path;                 ///< file it was read from; empty when built in memory
    int width = 0, height = 0;        ///< texels
    std::vector<Color> texels;        ///< width * height linear RGB radiances, row-major, each >= 0 and finite

    /// Texel at column x, row y (unchecked).
    const Color& at(int x, int y) const { return texels[size_t(y) * size_t(width) + size_t(x)]; }
    /// Bytes held by the texels.
    size_t bytes() const { return texels.size() * sizeof(Color); }
};

/// An environment as a scene or the command line names it.
struct Environment {
    std::shared_ptr<const EnvironmentImage> image;  ///< never null in a valid environment
    float rotation_deg = 0.f;         ///< turn about +Y, degrees, right-hand rule (+90 moves the map's centre from +X to -Z)
    float exposure_stops = 0.f;       ///< the map's radiance is scaled by 2^exposure_stops
    bool visible = true;              ///< false: camera rays that miss show the background colour instead
    /// The light not extracted as lights, as radiance SH coefficients (bands 0-2, world space;
    /// src/shading/environment_map.h): the ambient term. Set by the importer with the lights.
    std::optional<std::array<Color, 9>> ambient_sh;
    /// Luminance above which texels were extracted as lights, set by the importer with the lights
    /// (infinite: nothing extracted). The residual scales each texel by min(1, threshold / luminance);
    /// rough reflections read it where the lights' highlights bring the rest (docs/environment.md).
    float extraction_threshold = kInfinity;
};

}  // namespace whitted
