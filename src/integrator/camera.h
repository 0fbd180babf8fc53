// Camera rays from a Scene camera (perspective or orthographic, glTF conventions).
#pragma once

#include <span>

#include "accel/accelerator.h"
#include "integrator/scene_view.h"
#include "scene/scene.h"

namespace whitted {

struct ImageSize {
    int width = 0, height = 0;
};

/// Output resolution: the camera's aspect ratio (or 4:3 when the file gives none) completes a
/// missing dimension; when both are given they win and the field of view widens or narrows
/// horizontally (pixels stay square, nothing is stretched). 0 = not given. Default width 640.
ImageSize resolve_image_size(const Camera& camera, int width, int height);

/// Generates world-space camera rays for an image of the given size.
class CameraModel {
public:
    CameraModel(const Camera& camera, int width, int height);
    /// Ray through image position (x, y) in pixels, (0, 0) = top-left corner of the image,
    /// (width, height) = bottom-right; pixel centres are at +0.5. Direction is unit length.
    Ray generate(double x, double y) const;
    /// A row of rays: rays[i] = generate(x0 + i * dx, y), bit for bit. Perspective rows are
    /// computed in blocks of packed double arithmetic, so the divisions and square roots of
    /// neighbouring rays share instructions.
    void generate_row(double x0, double dx, double y, std::span<Ray> rays) const;
    /// Footprint of one pixel as a ray cone: perspective cameras spread by the angle one pixel
    /// subtends at the image centre (2 tan(yfov/2) / height), orthographic ones have a constant
    /// width of one pixel. Used for texture MIP selection, whatever the anti-aliasing mode.
    RayCone pixel_cone() const;

private:
    Ray make_ray(double x, double y) const;  ///< generate()'s body, inlined into generate_row()
    CameraType m_type;
    Vec3d m_origin, m_right, m_up, m_forward;  ///< world-space camera frame (unit axes)
    double m_half_w = 1, m_half_h = 1;         ///< image-plane half extents at distance 1 (or ortho mags)
    double m_znear = 0, m_zfar = 0;
    double m_ndc_x = 0, m_ndc_y = 0;           ///< 2 / width, 2 / height
    int m_width, m_height;
};

}  // namespace whitted
