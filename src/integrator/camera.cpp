#include "integrator/camera.h"

#include <cmath>

#include "core/error.h"

namespace whitted {

ImageSize resolve_image_size(const Camera& camera, int width, int height) {
    if (width < 0 || height < 0) throw Error(fmt::format("image size must be positive (got {}x{})", width, height));
    double aspect = camera.aspect > 0 ? camera.aspect
                    : camera.type == CameraType::Orthographic && camera.ymag > 0 ? camera.xmag / camera.ymag
                                                                                  : 4.0 / 3.0;
    if (!(aspect > 0) || !std::isfinite(aspect)) aspect = 4.0 / 3.0;
    ImageSize s{width, height};
    if (s.width == 0 && s.height == 0) s.width = 640;
    if (s.width == 0) s.width = std::max(1, int(std::lround(s.height * aspect)));
    if (s.height == 0) s.height = std::max(1, int(std::lround(s.width / aspect)));
    return s;
}

CameraModel::CameraModel(const Camera& camera, int width, int height)
    : m_type(camera.type), m_width(width), m_height(height) {
    const Mat4d& m = camera.world_from_camera;
    m_origin = m.apply_point(Vec3d(0.0));
    // Columns of the camera-to-world matrix; normalized so scaled camera nodes still work.
    m_right = normalize(m.apply_vector({1, 0, 0}));
    m_up = normalize(m.apply_vector({0, 1, 0}));
    m_forward = normalize(m.apply_vector({0, 0, -1}));
    const double image_aspect = double(width) / double(height);
    m_ndc_x = 2.0 / double(width);
    m_ndc_y = 2.0 / double(height);
    if (m_type == CameraType::Perspective) {
        m_half_h = std::tan(camera.yfov * 0.5);
        m_half_w = m_half_h * image_aspect;
    } else {
        m_half_h = camera.ymag;
        m_half_w = camera.ymag * image_aspect;
    }
    m_znear = std::max(0.0, camera.znear);
    m_zfar = camera.zfar > 0 ? camera.zfar : 0.0;
}

inline Ray CameraModel::make_ray(double x, double y) const {
    // Normalized device coordinates in [-1, 1], +y up. One division per ray (the reciprocal of
    // the length): this runs once per camera sample.
    const double sx = (x * m_ndc_x - 1.0) * m_half_w;
    const double sy = (1.0 - y * m_ndc_y) * m_half_h;
    Ray r;
    if (m_type == CameraType::Perspective) {
        Vec3d d = m_forward + m_right * sx + m_up * sy;
        const double len = length(d);
        r.org = Vec3f(m_origin);
        r.dir = Vec3f(d * (1.0 / len));
        // Near and far planes are distances along the view axis: convert to distances on the ray
        // (divide by the cosine to the axis, 1 / len).
        r.tnear = float(m_znear * len);
        r.tfar = m_zfar > 0 ? float(m_zfar * len) : kInfinity;
    } else {
        r.org = Vec3f(m_origin + m_right * sx + m_up * sy);
        r.dir = Vec3f(m_forward);
        r.tnear = float(m_znear);
        r.tfar = m_zfar > 0 ? float(m_zfar) : kInfinity;
    }
    return r;
}

Ray CameraModel::generate(double x, double y) const { return make_ray(x, y); }

namespace {

/// Rays per block of the vectorised perspective row (arrays of this length stay in L1).
constexpr size_t kRowBlock = 16;

/// What one block of a perspective row needs from the camera.
struct PerspectiveRow {
    double fx, fy, fz;     ///< forward
    double rx, ry, rz;     ///< right
    double ux, uy, uz;     ///< up * sy: the same product make_ray forms, per row
    double ndc_x, half_w;
    double x0, dx;
};

/// Directions and lengths of rays [begin, begin + kRowBlock) of a perspective row: make_ray's
/// operations in make_ray's order, one array per component, so the compiler turns the loop into
/// packed double arithmetic (sqrtpd and divpd included: camera.cpp is compiled with
/// -fno-math-errno, and the lengths are never negative). Packed IEEE operations round exactly as
/// the scalar ones, so every lane is bit for bit what generate() computes. Baseline SSE2 (2
/// doubles per instruction) on purpose: 256-bit code next to the renderer's SSE code costs more
/// than the shorter loop saves.
void perspective_block(const PerspectiveRow& c, size_t begin, float* __restrict dir_x, float* __restrict dir_y,
                       float* __restrict dir_z, double* __restrict len_out) {
    for (int i = 0; i < int(kRowBlock); ++i) {
        // The index as int: packed int32 -> double conversions exist, 64-bit ones need AVX-512
        // (rows are far shorter than 2^31; the value is the same).
        const double x = c.x0 + double(int(begin) + i) * c.dx;
        const double sx = (x * c.ndc_x - 1.0) * c.half_w;
        // d = forward + right * sx + up * sy, left to right as Vec3d's operators evaluate it.
        const double dx = (c.fx + c.rx * sx) + c.ux;
        const double dy = (c.fy + c.ry * sx) + c.uy;
        const double dz = (c.fz + c.rz * sx) + c.uz;
        const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
        const double inv = 1.0 / len;
        dir_x[i] = float(dx * inv);
        dir_y[i] = float(dy * inv);
        dir_z[i] = float(dz * inv);
        len_out[i] = len;
    }
}

}  // namespace

void CameraModel::generate_row(double x0, double dx, double y, std::span<Ray> rays) const {
    size_t i = 0;
    if (m_type == CameraType::Perspective) {
        const double sy = (1.0 - y * m_ndc_y) * m_half_h;
        const Vec3d up_sy = m_up * sy;
        const PerspectiveRow c{m_forward.x, m_forward.y, m_forward.z, m_right.x, m_right.y, m_right.z,
                               up_sy.x,     up_sy.y,     up_sy.z,     m_ndc_x,   m_half_w,  x0, dx};
        const Vec3f org(m_origin);
        alignas(32) float dir_x[kRowBlock], dir_y[kRowBlock], dir_z[kRowBlock];
        alignas(32) double len[kRowBlock];
        for (; i + kRowBlock <= rays.size(); i += kRowBlock) {
            perspective_block(c, i, dir_x, dir_y, dir_z, len);
            for (size_t j = 0; j < kRowBlock; ++j) {
                Ray& r = rays[i + j];
                r.org = org;
                r.dir = Vec3f(dir_x[j], dir_y[j], dir_z[j]);
                r.tnear = float(m_znear * len[j]);
                r.tfar = m_zfar > 0 ? float(m_zfar * len[j]) : kInfinity;
            }
        }
    }
    // The rest of the row (and orthographic rows, which need no square root) one ray at a time.
    for (; i < rays.size(); ++i) rays[i] = make_ray(x0 + double(i) * dx, y);
}

RayCone CameraModel::pixel_cone() const {
    const double pixel = 2.0 * m_half_h / double(m_height);
    if (m_type == CameraType::Perspective) return RayCone{0.f, float(pixel)};
    return RayCone{float(pixel), 0.f};
}

}  // namespace whitted
