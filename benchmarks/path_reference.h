// A Monte Carlo path tracer over a Renderer's scene view and accelerator: the converged reference
// that `whitted bench env --path-reference` holds the occluded environment light against
// (issue 45's targets). It is a measuring instrument, not a render mode: unidirectional, with
// one environment sample per non-delta vertex (texels in proportion to luminance x solid angle)
// combined with BSDF sampling by multiple importance sampling (power heuristic). It refuses
// punctual lights, scenes without an environment and classic (scene-file) materials. Light
// reaching a diffuse surface through a mirror or glass (caustics) is found by BSDF sampling
// alone, so under maps with small bright lamps it converges slowly.
//
// Materials are the glTF 2.0 metallic-roughness BRDF as the specification's Appendix B writes
// it, not whitted's mapping of it: Lambert diffuse and Smith height-correlated GGX specular,
// mixed by Schlick's Fresnel at V.H (dielectric F0 from KHR_materials_ior / specular), metal
// F0 = base colour; KHR_materials_transmission as a smooth transmission (straight through a
// thin-walled surface; refracted by Snell into a KHR_materials_volume, without absorption);
// emission. Roughness below kDeltaRoughness is a perfect mirror. The layered extensions
// (clearcoat, sheen, ...) and occlusion textures are not evaluated (the base layer only).
// Every bounce is followed (Russian roulette after the third), so interreflection is included:
// the light whitted's method leaves out.
//
// Deterministic: each pixel's samples come from a generator seeded by the pixel and the sample
// index, so the image does not depend on the thread count.
#pragma once

#include <cstdint>
#include <string>

#include "film/film.h"
#include "integrator/render.h"

namespace whitted::app {

struct PathSettings {
    int spp = 256;          ///< paths per pixel
    int max_bounces = 64;   ///< surface interactions per path at most
    bool pixel_area = false;  ///< spread the paths over each pixel (box filter); false = through its centre
    uint64_t seed = 0;      ///< another seed gives an independent image of the same expectation
};

struct PathStats {
    uint64_t paths = 0;
    uint64_t segments = 0;    ///< rays traced (camera and bounces)
    double seconds = 0.0;     ///< wall time of the render
};

/// Why path_trace() refuses `renderer`'s scene (no environment, punctual lights other than those
/// extracted from the environment, which it sees as part of the map, or a classic material), or
/// empty when it does not.
std::string path_trace_refusal(const Renderer& renderer);

/// Path-traced image of `renderer`'s scene at its image size and camera, on `threads` workers
/// (0 = all). Throws whitted::Error when the scene has punctual lights, no environment or a
/// classic material.
Film path_trace(const Renderer& renderer, const PathSettings& settings, int threads, PathStats* stats = nullptr);

}  // namespace whitted::app
