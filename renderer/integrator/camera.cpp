#include "renderer/integrator/camera.h"

#include <cmath>

#include "renderer/core/error.h"

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
    // the length): this runs once per camera sample, next to a cheap Embree miss for background.
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

void CameraModel::generate_row(double x0, double dx, double y, std::span<Ray> rays) const {
    // make_ray is inlined here, so consecutive rays' divisions overlap.
    for (size_t i = 0; i < rays.size(); ++i) rays[i] = make_ray(x0 + double(i) * dx, y);
}

RayCone CameraModel::pixel_cone() const {
    const double pixel = 2.0 * m_half_h / double(m_height);
    if (m_type == CameraType::Perspective) return RayCone{0.f, float(pixel)};
    return RayCone{float(pixel), 0.f};
}

}  // namespace whitted
