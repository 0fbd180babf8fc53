#include "renderer/integrator/whitted_integrator.h"

#include <cmath>
#include <iterator>
#include <span>
#include <utility>

#include "renderer/core/error.h"
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

}  // namespace

KernelFeatures select_kernel(const SceneFeatures& scene, const IntegratorSettings& settings) {
    if (!settings.specialize) return kGeneralKernel;
    KernelFeatures k;
    k.tables = true;
    k.attributes = scene.varying;
    k.transmission = !scene.opaque();
    k.mirror = scene.mirror || k.transmission;  // total internal reflection turns kt into kr
    return k;
}

std::string kernel_name(const KernelFeatures& k) {
    if (k == kGeneralKernel) return "general";
    std::string s = "specialised:";
    s += k.transmission ? " transmission," : " opaque,";
    s += k.mirror ? (k.transmission ? " reflection+refraction," : " reflection only,") : " no recursion,";
    s += k.attributes ? " textures/vertex colors" : " constant materials (no UVs)";
    if (k.tables) s += ", light culling";
    return s;
}

namespace {

/// Every kernel the selection can return, and the general one.
constexpr KernelFeatures kKernels[] = {
    kGeneralKernel,
    {false, false, false, true}, {true, false, false, true},  // opaque, no recursion
    {false, true, false, true},  {true, true, false, true},   // opaque mirrors
    {false, true, true, true},   {true, true, true, true},    // glass (and mirrors)
};

}  // namespace

WhittedIntegrator::WhittedIntegrator(const SceneView& view, const Accelerator& accel, const IntegratorSettings& settings)
    : m_view(view), m_accel(accel), m_settings(settings),
      m_kernel(select_kernel(view.analysis().features, settings)) {
    // The instantiation for the selected features, chosen once (no per-ray dispatch below).
    auto pick = [&]<size_t... I>(std::index_sequence<I...>) {
        ((m_kernel == kKernels[I] ? (void)(m_trace = kernel_entry<kKernels[I]>()) : (void)0), ...);
    };
    pick(std::make_index_sequence<std::size(kKernels)>{});
    RT_CHECK(m_trace != nullptr);
}

template <KernelFeatures K>
Color WhittedIntegrator::trace_kernel(const Ray& ray, RayKind kind, int depth, RayCounters& counters,
                                      PrimaryInfo* primary, const RayCone& cone, float weight) const {
    count(counters, kind);
    const Hit hit = m_accel.intersect(ray, kind);
    if (!hit.valid()) return m_settings.background;
    return sanitize(shade<K>(ray, hit, depth, counters, primary, cone, weight));
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

// The kernel. Every `if constexpr` below removes work a scene cannot need; the operations that
// remain run in the same order in every instantiation, so all kernels give bit-identical results
// on the scenes they are selected for (-ffp-contract=off keeps the compiler from fusing them).
template <KernelFeatures K>
Color WhittedIntegrator::shade(const Ray& ray, const Hit& hit, int depth, RayCounters& counters,
                               PrimaryInfo* primary, const RayCone& cone, float weight) const {
    const Scene& scene = m_view.scene();
    // Per material, only what it needs: a constant material (no textures, no vertex colors) needs
    // no UVs, colors or footprint, and its coefficients come from the analysis' table (the same
    // mapping, evaluated once at load).
    const MaterialFeatures& mf = m_view.analysis().materials[scene.geom_material(hit.geom)];
    SurfacePoint sp;
    if constexpr (!K.attributes) sp = m_view.surface<false>(ray, hit, cone);
    else if constexpr (!K.tables) sp = m_view.surface<true>(ray, hit, cone);
    else sp = mf.varying ? m_view.surface<true>(ray, hit, cone) : m_view.surface<false>(ray, hit, cone);
    WhittedCoeffs c;
    if constexpr (!K.tables) c = m_view.coefficients(sp);
    else if constexpr (!K.attributes) c = mf.constant;
    else c = mf.varying ? m_view.coefficients(sp) : mf.constant;
    const Material& mat = scene.materials[sp.material];
    // Secondary rays start where this cone arrived and keep its spread. Surface curvature would
    // widen (convex mirrors) or narrow it; it is ignored (flat-surface propagation).
    const RayCone secondary{cone.width_at(hit.t), cone.spread};

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
        auto add_light = [&](const Light& light) {
            LightSample ls = sample_light(light, sp.p);
            if (is_black(ls.intensity)) {  // beyond the range window or outside the spot cone
                ++counters.shadow_skipped_unreached;
                return;
            }
            const float n_dot_l = dot(N, ls.L);
            // The seed's `lum`: light only when N.L > 0 (shading normal). A light below the flat
            // facet but above the smooth surface still counts; the shadow ray decides.
            if (n_dot_l <= 0.f) {
                ++counters.shadow_skipped_facing;
                return;
            }
            Ray shadow;
            shadow.org = shadow_org;
            if (light.type == LightType::Directional) {
                shadow.dir = ls.L;
                shadow.tfar = kInfinity;
            } else {
                Vec3f to_light = Vec3f(light.position) - shadow_org;
                float d = length(to_light);
                if (!(d > 0.f)) return;
                shadow.dir = to_light / d;
                shadow.tfar = d * (1.f - 1e-5f);
            }
            count(counters, RayKind::Shadow);
            const Color s = m_accel.transmittance(shadow);
            if (is_black(s)) return;
            Color local = c.kd * n_dot_l;
            if (!is_black(c.ks)) {
                const Vec3f H = normalize(ls.L + V);
                local += c.ks * std::pow(std::max(0.f, dot(N, H)), c.n);
            }
            // Opaque scenes: s is exactly 1 here (nothing passes partially), and x * 1 == x.
            if constexpr (K.transmission) result += ls.intensity * s * local;
            else result += ls.intensity * local;
        };
        if (diffuse_or_specular) {
            if constexpr (K.tables) {
                // Only the lights that can reach this object (SceneAnalysis light reach).
                const std::span<const uint32_t> reach = m_view.lights_reaching(hit);
                counters.shadow_skipped_unreached += scene.lights.size() - reach.size();
                for (const uint32_t l : reach) add_light(scene.lights[l]);
            } else {
                for (const Light& light : scene.lights) add_light(light);
            }
        }

        // Recursive rays: Ks R + Kt T.
        if constexpr (K.mirror || K.transmission) {
            if (depth < m_settings.max_depth) {
                Color kr = c.kr, kt = c.kt;
                const float cos_v = std::clamp(dot(N, V), 0.f, 1.f);
                if (m_settings.fresnel) {
                    // Schlick: the mirror weight follows F(theta) and transmission takes what is left.
                    const FresnelWeights fw = schlick_weights(c.ks, c.kr, c.kt, cos_v);
                    kr = fw.kr;
                    kt = fw.kt;
                }
                // Hall & Greenberg (1983): a branch whose accumulated weight falls below min_weight
                // cannot change the pixel visibly; it is not traced.
                if constexpr (K.transmission) {
                    const float wt = weight * max_component(kt);
                    if (!is_black(kt) && wt < m_settings.min_weight) ++counters.secondary_skipped_cutoff;
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
                            result += kt * trace_kernel<K>(t, RayKind::Refraction, depth + 1, counters, nullptr,
                                                           secondary, wt);
                        } else {
                            kr += kt;  // the transmitted energy goes to reflection
                        }
                    }
                }
                const float wr = weight * max_component(kr);
                if (!is_black(kr) && wr < m_settings.min_weight) ++counters.secondary_skipped_cutoff;
                if (!is_black(kr) && wr >= m_settings.min_weight) {
                    Vec3f R = reflect(V, N);
                    if (dot(R, Ng) <= 0.f) R = reflect(V, Ng);
                    Ray r;
                    r.org = offset_ray_origin(sp.p, Ng);
                    r.dir = normalize(R);
                    result += kr * trace_kernel<K>(r, RayKind::Reflection, depth + 1, counters, nullptr, secondary, wr);
                }
            }
        }
    }

    if constexpr (K.transmission) {
        // Beer-Lambert: leaving a volume, the light travelled `t` inside it.
        if (!front && !c.thin && !is_black(c.absorption)) result *= exp_neg(c.absorption * hit.t);

        // alpha BLEND: partial coverage mixed with what lies straight behind.
        if (mat.model == MaterialModel::GltfPbr && mat.alpha_mode == AlphaMode::Blend) {
            float alpha;
            if constexpr (K.tables) alpha = mf.varying ? std::clamp(m_view.material_inputs(mat, sp).base_color.w, 0.f, 1.f)
                                                       : mf.constant_alpha;
            else alpha = std::clamp(m_view.material_inputs(mat, sp).base_color.w, 0.f, 1.f);
            if (alpha < 1.f) {
                Ray behind;
                behind.org = offset_ray_origin(sp.p, -Ng);
                behind.dir = ray.dir;
                // Below min_weight the branch behind is dropped (contributes 0) like the others.
                const float wb = weight * (1.f - alpha);
                Color b = m_settings.background;
                if (depth < m_settings.max_depth) {
                    if (wb >= m_settings.min_weight)
                        b = trace_kernel<K>(behind, RayKind::Refraction, depth + 1, counters, nullptr, secondary, wb);
                    else {
                        b = Color(0.f);
                        ++counters.secondary_skipped_cutoff;
                    }
                }
                result = result * alpha + b * (1.f - alpha);
            }
        }
    }
    return result;
}

}  // namespace whitted
