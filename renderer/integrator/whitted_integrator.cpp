#include "renderer/integrator/whitted_integrator.h"

#include <cmath>

#include "renderer/core/ray_offset.h"
#include "shading/light_sample.h"
#include "shading/optics.h"

namespace whitted {

namespace {

void count(RayCounters& c, RayKind kind) {
    switch (kind) {
        case RayKind::Camera: ++c.camera; break;
        case RayKind::Shadow: ++c.shadow; break;
        case RayKind::Reflection: ++c.reflection; break;
        case RayKind::Refraction: ++c.refraction; break;
    }
}

Color sanitize(const Color& c) {
    return {std::isfinite(c.x) ? c.x : 0.f, std::isfinite(c.y) ? c.y : 0.f, std::isfinite(c.z) ? c.z : 0.f};
}

Color exp_neg(const Color& c) { return {std::exp(-c.x), std::exp(-c.y), std::exp(-c.z)}; }

float max_component(const Color& c) { return std::max(c.x, std::max(c.y, c.z)); }

}  // namespace

Color WhittedIntegrator::trace(const Ray& ray, RayKind kind, int depth, RayCounters& counters,
                               PrimaryInfo* primary, const RayCone& cone, float weight) const {
    count(counters, kind);
    const Hit hit = m_accel.intersect(ray, kind);
    if (!hit.valid()) return m_settings.background;
    return sanitize(shade(ray, hit, depth, counters, primary, cone, weight));
}

void WhittedIntegrator::probe(const Ray& ray, RayCounters& counters, PrimaryInfo& primary) const {
    ++counters.aov_probe;
    const Hit hit = m_accel.intersect(ray, RayKind::Camera);
    if (!hit.valid()) return;
    const SurfacePoint sp = m_view.surface(ray, hit);
    const WhittedCoeffs c = m_view.coefficients(sp);
    // The same orientation rules as shade().
    const Vec3f V = -ray.dir;
    const bool front = dot(sp.ng, V) >= 0.f;
    Vec3f N = front ? sp.ns : -sp.ns;
    if (dot(N, V) <= 0.f) N = front ? sp.ng : -sp.ng;
    primary.hit = true;
    primary.depth = hit.t;
    primary.normal = N;
    primary.albedo = c.kd + c.kr + c.kt;
    primary.prim = hit.prim;
    primary.inst = hit.inst;
}

Color WhittedIntegrator::shade(const Ray& ray, const Hit& hit, int depth, RayCounters& counters,
                               PrimaryInfo* primary, const RayCone& cone, float weight) const {
    const Scene& scene = m_view.scene();
    const SurfacePoint sp = m_view.surface(ray, hit, cone);
    // Secondary rays start where this cone arrived and keep its spread. Surface curvature would
    // widen (convex mirrors) or narrow it; it is ignored (flat-surface propagation).
    const RayCone secondary{cone.width_at(hit.t), cone.spread};
    const Material& mat = scene.materials[sp.material];
    const WhittedCoeffs c = m_view.coefficients(sp);

    // Orient the frame toward the viewer. `front` also says whether a ray enters the medium
    // (hits the front face by winding) or leaves it: decided on the geometric normal.
    const Vec3f V = -ray.dir;
    const bool front = dot(sp.ng, V) >= 0.f;
    const Vec3f Ng = front ? sp.ng : -sp.ng;
    Vec3f N = front ? sp.ns : -sp.ns;
    if (dot(N, V) <= 0.f) N = Ng;  // shading normal facing away from the viewer: fall back

    if (primary) {
        primary->hit = true;
        primary->depth = hit.t;
        primary->normal = N;
        primary->albedo = c.kd + c.kr + c.kt;
        primary->prim = hit.prim;
        primary->inst = hit.inst;
    }

    // KHR_materials_unlit: the color is the answer.
    Color result = c.emission;
    const bool unlit = mat.model == MaterialModel::GltfPbr && mat.unlit;
    if (!unlit) {
        // Local model: I = Ia Ka + sum_i Is_i fat_i s_i (kd (N.L) + ks (N.H)^n).
        result += m_settings.ambient * c.ka;
        const Vec3f shadow_org = offset_ray_origin(front ? sp.p_shadow : sp.p, Ng);
        const bool diffuse_or_specular = !is_black(c.kd) || !is_black(c.ks);
        for (const Light& light : scene.lights) {
            if (!diffuse_or_specular) break;
            LightSample ls = sample_light(light, sp.p);
            if (is_black(ls.intensity)) continue;
            const float n_dot_l = dot(N, ls.L);
            // The seed's `lum`: light only when N.L > 0 (shading normal). A light below the flat
            // facet but above the smooth surface still counts; the shadow ray decides.
            if (n_dot_l <= 0.f) continue;
            Ray shadow;
            shadow.org = shadow_org;
            if (light.type == LightType::Directional) {
                shadow.dir = ls.L;
                shadow.tfar = kInfinity;
            } else {
                Vec3f to_light = Vec3f(light.position) - shadow_org;
                float d = length(to_light);
                if (!(d > 0.f)) continue;
                shadow.dir = to_light / d;
                shadow.tfar = d * (1.f - 1e-5f);
            }
            count(counters, RayKind::Shadow);
            const Color s = m_accel.transmittance(shadow);
            if (is_black(s)) continue;
            Color local = c.kd * n_dot_l;
            if (!is_black(c.ks)) {
                const Vec3f H = normalize(ls.L + V);
                local += c.ks * std::pow(std::max(0.f, dot(N, H)), c.n);
            }
            result += ls.intensity * s * local;
        }

        // Recursive rays: Ks R + Kt T.
        if (depth < m_settings.max_depth) {
            Color kr = c.kr, kt = c.kt;
            const float cos_v = std::clamp(dot(N, V), 0.f, 1.f);
            if (m_settings.fresnel) {
                // Schlick: the mirror weight follows F(theta) and transmission takes what is left.
                const Color F = schlick(c.ks, cos_v);
                for (int i = 0; i < 3; ++i) {
                    kr[i] = c.ks[i] > 0.f ? c.kr[i] * F[i] / c.ks[i] : 0.f;
                    kt[i] = c.ks[i] < 1.f ? c.kt[i] * (1.f - F[i]) / (1.f - c.ks[i]) : 0.f;
                }
            }
            // Hall & Greenberg (1983): a branch whose accumulated weight falls below min_weight
            // cannot change the pixel visibly; it is not traced.
            const float wt = weight * max_component(kt);
            if (!is_black(kt) && wt >= m_settings.min_weight) {
                Ray t;
                t.org = offset_ray_origin(sp.p, -Ng);
                bool transmitted = true;
                if (c.thin) {
                    t.dir = ray.dir;  // thin-walled: straight through
                } else {
                    const float eta = front ? 1.f / c.ior : c.ior;
                    auto dir = refract(ray.dir, N, eta);
                    if (dir && dot(*dir, Ng) < 0.f) t.dir = *dir;
                    else transmitted = false;  // total internal reflection
                }
                if (transmitted) {
                    result += kt * trace(t, RayKind::Refraction, depth + 1, counters, nullptr, secondary, wt);
                } else {
                    kr += kt;  // the transmitted energy goes to reflection
                }
            }
            const float wr = weight * max_component(kr);
            if (!is_black(kr) && wr >= m_settings.min_weight) {
                Vec3f R = reflect(V, N);
                if (dot(R, Ng) <= 0.f) R = reflect(V, Ng);
                Ray r;
                r.org = offset_ray_origin(sp.p, Ng);
                r.dir = normalize(R);
                result += kr * trace(r, RayKind::Reflection, depth + 1, counters, nullptr, secondary, wr);
            }
        }
    }

    // Beer-Lambert: leaving a volume, the light travelled `t` inside it.
    if (!front && !c.thin && !is_black(c.absorption)) result *= exp_neg(c.absorption * hit.t);

    // alpha BLEND: partial coverage mixed with what lies straight behind.
    if (mat.model == MaterialModel::GltfPbr && mat.alpha_mode == AlphaMode::Blend) {
        const float alpha = std::clamp(m_view.material_inputs(mat, sp).base_color.w, 0.f, 1.f);
        if (alpha < 1.f) {
            Ray behind;
            behind.org = offset_ray_origin(sp.p, -Ng);
            behind.dir = ray.dir;
            Color b = depth < m_settings.max_depth ? trace(behind, RayKind::Refraction, depth + 1, counters, nullptr,
                                                           secondary, weight * (1.f - alpha))
                                                   : m_settings.background;
            result = result * alpha + b * (1.f - alpha);
        }
    }
    return result;
}

}  // namespace whitted
