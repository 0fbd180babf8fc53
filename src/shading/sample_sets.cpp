#include "shading/sample_sets.h"

#include <algorithm>
#include <cmath>

namespace whitted {

float radical_inverse2(uint32_t k) {
    k = (k << 16u) | (k >> 16u);
    k = ((k & 0x55555555u) << 1u) | ((k & 0xAAAAAAAAu) >> 1u);
    k = ((k & 0x33333333u) << 2u) | ((k & 0xCCCCCCCCu) >> 2u);
    k = ((k & 0x0F0F0F0Fu) << 4u) | ((k & 0xF0F0F0F0u) >> 4u);
    k = ((k & 0x00FF00FFu) << 8u) | ((k & 0xFF00FF00u) >> 8u);
    return float(k) * 2.3283064365386963e-10f;
}

void tangent_frame(const Vec3f& n, Vec3f& t, Vec3f& b) {
    const float sign = std::copysign(1.f, n.z);
    const float a = -1.f / (sign + n.z);
    const float c = n.x * n.y * a;
    t = {1.f + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
}

SmoothFrame::SmoothFrame(const Vec3f& normal) : n(normal) {
    // The tangent follows the fixed axis (1, 2, 3)/sqrt(14) projected onto the tangent plane; near
    // that axis (or its opposite) a second one takes over.
    const Vec3f axis(0.26726124f, 0.53452248f, 0.80178373f);
    Vec3f c = cross(axis, n);
    if (dot(c, c) < 1e-4f) c = cross(Vec3f(0.87287156f, -0.21821789f, 0.43643578f), n);
    t = normalize(c);
    b = cross(n, t);
}

Vec3f cosine_direction(float u, float v) {
    const float a = 2.f * u - 1.f, b = 2.f * v - 1.f;
    float r, phi;
    if (a == 0.f && b == 0.f) {
        r = 0.f, phi = 0.f;
    } else if (std::abs(a) > std::abs(b)) {
        r = a, phi = (kPi / 4.f) * (b / a);
    } else {
        r = b, phi = kPi / 2.f - (kPi / 4.f) * (a / b);
    }
    const float x = r * std::cos(phi), y = r * std::sin(phi);
    return normalize(Vec3f(x, y, std::sqrt(std::max(0.f, 1.f - x * x - y * y))));
}

HemisphereGrid cosine_grid(int count) {
    HemisphereGrid g;
    g.n = std::max(1, int(std::lround(std::sqrt(double(std::max(count, 1))))));
    // Each cell's direction: its mean cos(theta) and mean azimuth over 16 x 16 points of the cell, so
    // that the cells together weigh the hemisphere's cosine exactly (a cell's midpoint in (u, v)
    // leans toward the pole: 36 midpoints average cos(theta) 0.705 instead of 2/3).
    constexpr int kSub = 16;
    for (int y = 0; y < g.n; ++y)
        for (int x = 0; x < g.n; ++x) {
            double z = 0.0, dx = 0.0, dy = 0.0;
            for (int j = 0; j < kSub; ++j)
                for (int i = 0; i < kSub; ++i) {
                    const Vec3f d = cosine_direction((float(x) + (float(i) + 0.5f) / kSub) / float(g.n),
                                                     (float(y) + (float(j) + 0.5f) / kSub) / float(g.n));
                    z += d.z, dx += d.x, dy += d.y;
                }
            z /= double(kSub * kSub);
            const double planar = std::sqrt(dx * dx + dy * dy), s = std::sqrt(std::max(0.0, 1.0 - z * z));
            g.centres.push_back(planar > 0.0 ? normalize(Vec3f(float(dx / planar * s), float(dy / planar * s), float(z)))
                                             : Vec3f(0.f, 0.f, 1.f));
        }
    return g;
}

std::array<int, 4> HemisphereGrid::neighbours(int k) const {
    const int x = k % n, y = k / n;
    return {x > 0 ? k - 1 : -1, x + 1 < n ? k + 1 : -1, y > 0 ? k - n : -1, y + 1 < n ? k + n : -1};
}

Vec3f ggx_half_vector(float xi1, float xi2, float alpha) {
    const float a2 = alpha * alpha;
    const float cos2 = (1.f - xi1) / (1.f + (a2 - 1.f) * xi1);
    const float cos_h = std::sqrt(cos2), sin_h = std::sqrt(std::max(0.f, 1.f - cos2));
    const float phi = 2.f * kPi * xi2;
    return {sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h};
}

}  // namespace whitted
