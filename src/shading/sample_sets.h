// Fixed sets of directions: the same pattern at every shading point, so that what they estimate
// is deterministic and free of noise (the environment's prefilter, its occlusion and the glossy
// rays; docs/environment.md).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/vecmath.h"

namespace whitted {

/// Radical inverse in base 2 (van der Corput), the second Hammersley coordinate.
float radical_inverse2(uint32_t k);

/// Orthonormal tangents of unit n (Duff et al. 2017, branchless). Discontinuous where n.z changes
/// sign: for frames that only orient a pattern about a fixed n (the prefilter's texels).
void tangent_frame(const Vec3f& n, Vec3f& t, Vec3f& b);

/// An orthonormal frame about unit n that turns smoothly with n everywhere except within about
/// 0.6 degrees of +-kFrameAxis (a direction no axis-aligned surface has), so a fixed pattern
/// placed in it changes smoothly over a curved surface and not at all over a plane.
struct SmoothFrame {
    Vec3f t, b, n;
    explicit SmoothFrame(const Vec3f& normal);
    Vec3f to_world(const Vec3f& d) const { return t * d.x + b * d.y + n * d.z; }
};

/// The unit direction about +z at (u, v) in [0, 1]^2: Shirley and Chiu's concentric map onto the
/// unit disk, lifted onto the hemisphere (Malley's method). Equal areas of (u, v) are equal shares
/// of the cosine-weighted hemisphere, and squares stay nearly square: no cell is a thin wedge.
Vec3f cosine_direction(float u, float v);

/// The cosine-weighted hemisphere about +z cut into n x n cells of equal weight, squares of (u, v)
/// under cosine_direction, with one direction per cell at the cell's mean cos(theta) and mean
/// azimuth; cell k covers u in [k % n, k % n + 1) / n and v in [k / n, k / n + 1) / n.
struct HemisphereGrid {
    int n = 0;
    std::vector<Vec3f> centres;
    size_t size() const { return centres.size(); }
    /// The cells sharing an edge with cell k; -1 where there is none (the horizon).
    std::array<int, 4> neighbours(int k) const;
};

/// The grid of about `count` cells: n = max(1, round(sqrt(count))).
HemisphereGrid cosine_grid(int count);

/// The GGX (Trowbridge-Reitz) half vector about +z for the point (xi1, xi2) of the unit square,
/// distributed as D(h) cos(theta_h) with alpha = roughness^2.
Vec3f ggx_half_vector(float xi1, float xi2, float alpha);

/// GGX's D(h) at cos^2(theta_h) = cos2 for a2 = alpha^2: a2 / (pi ((a2 - 1) cos2 + 1)^2).
inline float ggx_distribution(float cos2, float a2) {
    const float denom = cos2 * (a2 - 1.f) + 1.f;
    return a2 / (kPi * denom * denom);
}

}  // namespace whitted
