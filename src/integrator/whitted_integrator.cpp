#include "integrator/whitted_integrator.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <utility>

#include "core/error.h"
#include "core/uninitialized.h"
#include "integrator/contacts.h"
#include "shading/local_model.h"
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

PrimaryInfo first_hit(const Hit& hit, const Vec3f& N, const WhittedCoeffs& c) {
    return {true, hit.t, N, c.kd + c.kr + c.kt, hit.prim, hit.inst};
}

}  // namespace

// Every `if constexpr` below removes work a scene cannot need; the operations that remain run in
// the same order in every kernel, so all kernels give bit-identical results on the scenes they are
// selected for (-ffp-contract=off keeps the compiler from fusing them).

template <KernelFeatures K>
Color WhittedIntegrator::shade(const Ray& ray, const Hit& hit, int depth, RayCounters& counters,
                               PrimaryInfo* primary, const RayCone& cone, float weight) const {
    if (!hit.valid()) return missed(ray, depth, cone);
    const MaterialFeatures& mf = features(hit);
    const SurfacePoint sp = surface_point<K>(ray, hit, mf, cone);
    if constexpr (K.transmission) {
        // An opaque surface under a transmissive one lying on it is what the ray sees.
        if (const std::optional<Hit> cover = covering_surface(hit, sp, counters))
            return shade<K>(ray, *cover, depth, counters, primary, cone, weight);
    }
    const ShadingFrame frame = shading_frame(sp, ray.dir);
    WhittedCoeffs varying;
    LayerCoeffs layers;
    const LayerCoeffs* layered = nullptr;
    const WhittedCoeffs* coeffs;
    if constexpr (K.layers) {
        if (mf.layered) {
            varying = m_view.layered_coefficients(sp, layer_frame(sp, frame), layers);
            layered = &layers;
            coeffs = &varying;
        } else {
            coeffs = &coefficients<K>(mf, sp, varying);
        }
    } else {
        coeffs = &coefficients<K>(mf, sp, varying);
    }
    const WhittedCoeffs& c = *coeffs;
    const Shading s{ray, hit, sp, c, m_view.scene().materials[sp.material], mf, frame,
                    touching_medium<K>(hit, sp, c, counters), depth, RayCone{cone.width_at(hit.t), cone.spread},
                    weight, layered};
    if (primary) *primary = first_hit(hit, s.f.N, c);

    Color I = c.emission;
    const bool unlit = s.mat.model == MaterialModel::GltfPbr && s.mat.unlit;  // KHR_materials_unlit
    if (!unlit) {
        // I = emission + Ia ka + sum_i Is_i fat_i s_i (kd N.L_i + ks (N.H_i)^n) + kt T + kr R + kg G
        Color ambient = ambient_light(s.f.N) * c.ka;
        if constexpr (K.layers)
            if (layered) ambient += layered_ambient(s);
        I = direct_light<K>(I + ambient, s, counters);
        if (depth < m_settings.max_depth) {
            Color kt_T(0.f), kr_R(0.f);
            if constexpr (K.mirror || K.transmission) {
                auto [kr, kt] = secondary_weights(c.ks, c.kr, c.kt, std::clamp(dot(s.f.N, s.f.V), 0.f, 1.f),
                                                  m_settings.fresnel);
                kt_T = transmitted<K>(s, kt, kr, counters);  // total internal reflection adds kt to kr
                Color coat_R(0.f);
                if constexpr (K.layers)
                    if (layered) coat_R = coat_reflection<K>(s, kr, counters);  // may join the base's ray
                kr_R = reflected<K>(s, kr, s.f.N, counters);
                if (layered) kr_R += coat_R;
            }
            // In every kernel: rough opaque scenes cast no mirror rays.
            Color kg_G = glossy(s, c.kg, layered ? layers.glossy_normal : s.f.N, c.roughness, c.n, counters);
            if (layered && layers.coat_kg > 0.f)
                kg_G += glossy(s, Color(layers.coat_kg), layers.Nc, layers.coat_roughness, layers.coat_n, counters);
            I = I + kt_T + kr_R + kg_G;
        }
    }
    if constexpr (K.transmission) I = blend_behind<K>(s, absorbed(s, I), counters);
    return sanitize(I);
}

// ---- What surrounds the scene: the environment ------------------------------------------------

Color WhittedIntegrator::missed(const Ray& ray, int depth, const RayCone& cone) const {
    if (m_environment && (depth > 0 || (m_settings.environment_visible && m_environment->visible())))
        return m_environment->radiance(ray.dir, cone.spread);
    return m_settings.background;
}

Color WhittedIntegrator::ambient_light(const Vec3f& N) const {
    return m_ambient_sh ? sh9_irradiance(*m_ambient_sh, N) : m_settings.ambient;
}

Color WhittedIntegrator::layered_ambient(const Shading& s) const {
    const LayerCoeffs& l = *s.layers;
    Color a(0.f);
    if (!is_black(l.sheen_ambient)) a += ambient_light(s.f.N) * l.sheen_ambient;
    if (!is_black(l.kdt)) a += ambient_light(-s.f.N) * l.kdt;  // diffuse transmission: from behind
    return a;
}

// ---- Direct light: sum_i Is_i fat_i s_i (kd N.L_i + ks (N.H_i)^n) --------------------------

/// `sum` plus the light of every light source at the point; the terms are added to `sum` in light
/// order, the scene's own lights first, then those extracted from the environment (below). A light
/// casts no shadow ray where it cannot reach the point, faces it from behind, or gives it nothing
/// for the shadow factor to scale.
///
/// The extracted lights are many dim ones, so they take Ward's adaptive shadow testing (Ward,
/// "Adaptive Shadow Testing for Ray Tracing", 1991): sorted by what each could give the point
/// unshadowed, shadow rays are traced from the brightest down until what the untested ones could
/// still add, times the path weight, is below min_weight; the untested ones then add their
/// unshadowed light scaled by the fraction the tested ones let through. Nothing is dropped: with
/// min_weight = 0 every light is tested.
template <KernelFeatures K>
Color WhittedIntegrator::direct_light(Color sum, const Shading& s, RayCounters& counters) const {
    const WhittedCoeffs& c = s.c;
    if (is_black(c.kd) && is_black(c.ks) && !s.layers) return sum;
    std::optional<Vec3f> shadow_org;  // computed at the first light that needs a shadow ray
    std::optional<Vec3f> back_org;    // diffuse transmission: lights behind the surface
    struct Candidate {
        const Light* light;
        LightSample ls;
        Color potential;  // Is fat (kd N.L + ks (N.H)^n): the light's term if nothing shadows it
        float key;
        bool behind;      // seen through the surface (diffuse transmission)
    };
    thread_local std::vector<Candidate> environment;
    environment.clear();
    auto shadowed = [&](const Candidate& e) {
        if (!shadow_org) shadow_org = m_offset.origin(s.f.front ? s.sp.p_shadow : s.sp.p, s.sp.offset_scale, s.f.Ng);
        if (e.behind && !back_org) back_org = m_offset.origin(s.sp.p, s.sp.offset_scale, -s.f.Ng);
        const Color shadow = shadow_factor(*e.light, e.ls, e.behind ? *back_org : *shadow_org, counters);
        if (is_black(shadow)) return Color(0.f);
        // Opaque scenes: the shadow factor is exactly 1 here, and x * 1 == x.
        if constexpr (K.transmission) return e.potential * shadow;
        else return e.potential;
    };
    // The extracted lights' highlight scale depends on the material alone: once per point where
    // there are such lights (an environment), instead of once per light.
    const float environment_scale = m_view.environment() ? environment_highlight_scale(c.n) : 1.f;
    auto add_light = [&](uint32_t index) {
        const Light& light = m_view.scene().lights[index];
        const LightSample ls = m_view.sample_light(index, s.sp.p);
        if (is_black(ls.intensity)) {  // beyond its range window or outside its spot cone
            ++counters.shadow_skipped_unreached;
            return;
        }
        // Light only where N.L > 0 on the shading normal (or behind a diffusely transmitting
        // layered surface); the shadow ray decides the rest.
        const float n_dot_l = dot(s.f.N, ls.L);
        bool behind = false;
        if constexpr (K.layers) behind = s.layers && n_dot_l < 0.f && !is_black(s.layers->kdt);
        if (n_dot_l <= 0.f && !behind) {
            ++counters.shadow_skipped_facing;
            return;
        }
        Color term;
        if constexpr (K.layers) {
            term = s.layers ? layered_term(c, *s.layers, s.f.N, ls.L, s.f.V, n_dot_l, light.from_environment)
                            : local_term(c, s.f.N, ls.L, s.f.V, n_dot_l, light.from_environment ? environment_scale : 1.f);
        } else {
            term = local_term(c, s.f.N, ls.L, s.f.V, n_dot_l, light.from_environment ? environment_scale : 1.f);
        }
        if (is_black(term)) {  // kd = 0 and the highlight below its cutoff
            ++counters.shadow_skipped_zero;
            return;
        }
        Candidate e{&light, ls, ls.intensity * term, 0.f, behind};
        if (!light.from_environment) {
            sum += shadowed(e);
            return;
        }
        e.key = max_component(e.potential);
        environment.push_back(e);
    };
    if constexpr (K.tables) {
        // Only the lights that can reach this object (SceneAnalysis light reach).
        const std::span<const uint32_t> reach = m_view.lights_reaching(s.hit);
        counters.shadow_skipped_unreached += m_view.scene().lights.size() - reach.size();
        for (const uint32_t l : reach) add_light(l);
    } else {
        for (uint32_t l = 0; l < uint32_t(m_view.scene().lights.size()); ++l) add_light(l);
    }
    if (environment.empty()) return sum;

    // Brightest first; ties in light order, so the result does not depend on the sort. The keys
    // are not negative, so their bits order like their values: one integer per candidate, the
    // key's bits inverted (brightest first) above its index (light order).
    thread_local std::vector<uint64_t> order;
    order.resize(environment.size());
    for (size_t j = 0; j < environment.size(); ++j) {
        const float key = environment[j].key > 0.f ? environment[j].key : 0.f;  // -0 and NaN as 0
        order[j] = uint64_t(~std::bit_cast<uint32_t>(key)) << 32 | uint64_t(j);
    }
    std::sort(order.begin(), order.end());
    auto nth = [&](size_t k) -> const Candidate& { return environment[uint32_t(order[k])]; };
    Color untested(0.f);
    for (size_t k = 0; k < environment.size(); ++k) untested += nth(k).potential;
    Color tested(0.f), passed(0.f);
    size_t i = 0;
    for (; i < environment.size() && s.weight * max_component(untested) >= m_settings.min_weight; ++i) {
        const Color through = shadowed(nth(i));
        passed += through;
        tested += nth(i).potential;
        untested = untested - nth(i).potential;
        untested = Color(std::max(untested.x, 0.f), std::max(untested.y, 0.f), std::max(untested.z, 0.f));
    }
    sum += passed;
    if (i == environment.size()) return sum;
    counters.shadow_skipped_dim += environment.size() - i;
    untested = Color(0.f);  // summed again: the running difference above is not exact
    for (size_t j = i; j < environment.size(); ++j) untested += nth(j).potential;
    if (i == 0) return sum + untested;  // all of them together below min_weight: unshadowed
    const Color let_through(tested.x > 0.f ? passed.x / tested.x : 1.f, tested.y > 0.f ? passed.y / tested.y : 1.f,
                            tested.z > 0.f ? passed.z / tested.z : 1.f);
    return sum + untested * let_through;
}

Color WhittedIntegrator::shadow_factor(const Light& light, const LightSample& ls, const Vec3f& org,
                                       RayCounters& counters) const {
    Ray shadow;
    shadow.org = org;
    if (light.type == LightType::Directional) {
        shadow.dir = ls.L;
        shadow.tfar = kInfinity;
    } else {
        const Vec3f to_light = Vec3f(light.position) - org;
        const float d = length(to_light);
        if (!(d > 0.f)) return Color(0.f);
        shadow.dir = to_light / d;
        shadow.tfar = d * (1.f - 1e-5f);
    }
    count(counters, RayKind::Shadow);
    return m_accel.transmittance(shadow);
}

// ---- Recursive rays: kt T and kr R --------------------------------------------------------------

bool WhittedIntegrator::worth_tracing(float w, RayCounters& counters) const {
    // Hall & Greenberg (1983): a branch whose path weight is below min_weight cannot change the
    // pixel visibly.
    if (w < m_settings.min_weight) ++counters.secondary_skipped_cutoff;
    return w >= m_settings.min_weight;
}

/// kt T: the radiance of the refracted ray (Snell; straight on through thin-walled surfaces)
/// weighted by kt. On total internal reflection kt is added to kr and the result is 0.
template <KernelFeatures K>
Color WhittedIntegrator::transmitted(const Shading& s, const Color& kt, Color& kr, RayCounters& counters) const {
    if constexpr (!K.transmission) return Color(0.f);
    // Through a touching medium's face the light crosses both surfaces.
    const Color kt_through = s.other ? kt * s.other->c.kt : kt;
    const float w = s.weight * max_component(kt_through);
    if (is_black(kt) || !worth_tracing(w, counters)) return Color(0.f);
    Ray t = spawn_ray(m_offset, s.sp, -s.f.Ng, s.ray.dir);
    float eta = s.f.front ? 1.f / s.c.ior : s.c.ior;
    float other_eta = 1.f;
    if (s.other) {
        // One interface between the two media (no total internal reflection in a gap of zero
        // width), and the ray starts past both surfaces.
        other_eta = s.f.front ? s.other->c.ior : 1.f / s.other->c.ior;
        eta *= other_eta;
        const Vec3f past_other =
            m_offset.origin(s.other->p, std::max(s.sp.offset_scale, s.other->offset_scale), -s.f.Ng);
        if (dot(past_other - t.org, s.f.Ng) < 0.f) t.org = past_other;
    }
    if constexpr (K.layers) {
        if (s.layers && s.layers->dispersion > 0.f && !s.c.thin)
            return dispersed<K>(s, t, kt, kt_through, other_eta, w, kr, counters);
    }
    const std::optional<Vec3f> dir = transmitted_direction(s.ray.dir, s.f.N, s.f.Ng, eta, s.c.thin);
    if (!dir) {
        kr += kt;
        return Color(0.f);
    }
    t.dir = *dir;
    return kt_through * trace<K>(t, RayKind::Refraction, s.depth + 1, counters, nullptr, s.secondary, w);
}

/// The colour channel the current refracted ray carries after a dispersive surface split it
/// (-1: all three). Set around each channel's trace on this thread, so the surfaces below bend
/// that ray by the channel's own index of refraction instead of splitting it again.
static thread_local int t_dispersion_channel = -1;

/// kt T through a dispersive surface (KHR_materials_dispersion): one refracted ray per channel,
/// each bent by that channel's ior (dispersion_iors) and keeping that channel of its radiance; a
/// ray already carrying one channel stays one ray. Total internal reflection of a channel adds
/// its kt to kr. `other_eta`: the touching medium's factor of the relative index.
template <KernelFeatures K>
Color WhittedIntegrator::dispersed(const Shading& s, const Ray& t, const Color& kt, const Color& kt_through,
                                   float other_eta, float w, Color& kr, RayCounters& counters) const {
    const Color iors = dispersion_iors(s.c.ior, s.layers->dispersion);
    auto bent = [&](int k) {
        const float eta = (s.f.front ? 1.f / iors[k] : iors[k]) * other_eta;
        return transmitted_direction(s.ray.dir, s.f.N, s.f.Ng, eta, false);
    };
    struct Channel {  // sets the thread's channel for one trace, and restores it
        explicit Channel(int k) { t_dispersion_channel = k; }
        ~Channel() { t_dispersion_channel = -1; }
    };
    Color result(0.f);
    const int carried = t_dispersion_channel;
    for (int k = 0; k < 3; ++k) {
        if (carried >= 0 && k != carried) continue;
        if (!(kt[k] > 0.f)) continue;
        const std::optional<Vec3f> dir = bent(k);
        if (!dir) {
            kr[k] += kt[k];
            continue;
        }
        Ray tk = t;
        tk.dir = *dir;
        if (carried >= 0) return kt_through * trace<K>(tk, RayKind::Refraction, s.depth + 1, counters, nullptr, s.secondary, w);
        const Channel channel(k);
        result[k] = kt_through[k] * trace<K>(tk, RayKind::Refraction, s.depth + 1, counters, nullptr, s.secondary, w)[k];
    }
    return result;
}

/// kr R: the radiance of the mirror ray weighted by kr.
template <KernelFeatures K>
Color WhittedIntegrator::reflected(const Shading& s, const Color& kr, const Vec3f& N, RayCounters& counters) const {
    const float w = s.weight * max_component(kr);
    if (is_black(kr) || !worth_tracing(w, counters)) return Color(0.f);
    const Ray r = spawn_ray(m_offset, s.sp, s.f.Ng, mirror_direction(s.f.V, N, s.f.Ng));
    return kr * trace<K>(r, RayKind::Reflection, s.depth + 1, counters, nullptr, s.secondary, w);
}

/// The clearcoat's mirror ray: where the coat's normal is the base's, one ray carries both
/// weights (added to kr); else its own ray about the coat's normal.
template <KernelFeatures K>
Color WhittedIntegrator::coat_reflection(const Shading& s, Color& kr, RayCounters& counters) const {
    const LayerCoeffs& l = *s.layers;
    if (!(l.coat_kr > 0.f)) return Color(0.f);
    if (l.Nc == s.f.N) {
        kr += Color(l.coat_kr);
        return Color(0.f);
    }
    return reflected<K>(s, Color(l.coat_kr), l.Nc, counters);
}

// ---- Glossy reflection of the environment: kg G ----------------------------------------------

/// kg G: the split-sum prefilter (Karis 2013) about the mirror direction, the reflection the
/// mirror term gives up on rough surfaces. The lights extracted from the map already reflect
/// highlight_share(n) of their light as highlights, so that share of the extracted part is read
/// from the residual instead of the map. It sees the environment only, never the scene's geometry.
Color WhittedIntegrator::glossy(const Shading& s, const Color& kg, const Vec3f& N, float roughness, float n,
                                RayCounters& counters) const {
    if (!m_environment || is_black(kg)) return Color(0.f);
    if (!worth_tracing(s.weight * max_component(kg), counters)) return Color(0.f);
    const Vec3f R = mirror_direction(s.f.V, N, s.f.Ng);
    const Color G = m_environment->prefiltered(R, roughness);
    if (!m_environment->has_residual()) return kg * G;
    return kg * lerp(G, m_environment->residual_prefiltered(R, roughness), highlight_share(n));
}

// ---- Media and coverage: absorption, alpha blend ------------------------------------------------

/// Beer-Lambert along the ray's last segment, inside this medium (leaving it) or inside a
/// touching one (entering this one from it).
Color WhittedIntegrator::absorbed(const Shading& s, Color radiance) const {
    if (!s.f.front && !s.c.thin && !is_black(s.c.absorption)) radiance *= exp_neg(s.c.absorption * s.hit.t);
    if (s.f.front && s.other && !is_black(s.other->c.absorption))
        radiance *= exp_neg(s.other->c.absorption * s.hit.t);
    return radiance;
}

/// glTF alpha BLEND: partial coverage mixed with what lies straight behind the surface.
template <KernelFeatures K>
Color WhittedIntegrator::blend_behind(const Shading& s, const Color& radiance, RayCounters& counters) const {
    if (s.mat.model != MaterialModel::GltfPbr || s.mat.alpha_mode != AlphaMode::Blend) return radiance;
    float alpha;
    if constexpr (K.tables)
        alpha = s.mf.varying ? std::clamp(m_view.material_inputs(s.mat, s.sp).base_color.w, 0.f, 1.f) : s.mf.constant_alpha;
    else
        alpha = std::clamp(m_view.material_inputs(s.mat, s.sp).base_color.w, 0.f, 1.f);
    if (!(alpha < 1.f)) return radiance;
    const Ray behind = spawn_ray(m_offset, s.sp, -s.f.Ng, s.ray.dir);
    const float w = s.weight * (1.f - alpha);
    Color b = m_settings.background;  // past the depth limit
    if (s.depth < m_settings.max_depth) {
        if (w >= m_settings.min_weight) {
            b = trace<K>(behind, RayKind::Refraction, s.depth + 1, counters, nullptr, s.secondary, w);
        } else {  // below min_weight the branch behind contributes 0, like the others
            b = Color(0.f);
            ++counters.secondary_skipped_cutoff;
        }
    }
    return radiance * alpha + b * (1.f - alpha);
}

// ---- The hit, per kernel ------------------------------------------------------------------------

/// A constant material (no textures, no vertex colors) needs no UVs, colors or footprint.
template <KernelFeatures K>
SurfacePoint WhittedIntegrator::surface_point(const Ray& ray, const Hit& hit, const MaterialFeatures& mf,
                                              const RayCone& cone) const {
    if constexpr (!K.attributes) return m_view.surface<false>(ray, hit, cone);
    else if constexpr (!K.tables) return m_view.surface<true>(ray, hit, cone);
    else return mf.varying ? m_view.surface<true>(ray, hit, cone) : m_view.surface<false>(ray, hit, cone);
}

/// A constant material's coefficients come from the analysis' table (read in place, not copied);
/// others are evaluated into `varying`.
template <KernelFeatures K>
const WhittedCoeffs& WhittedIntegrator::coefficients(const MaterialFeatures& mf, const SurfacePoint& sp,
                                                     WhittedCoeffs& varying) const {
    if constexpr (!K.tables) return varying = m_view.coefficients(sp);
    else if constexpr (!K.attributes) return mf.constant;
    else return mf.varying ? (varying = m_view.coefficients(sp)) : mf.constant;
}

/// The medium of a touching dielectric beyond a hit on a non-thin dielectric (contacts.h).
template <KernelFeatures K>
std::optional<WhittedIntegrator::OtherMedium> WhittedIntegrator::touching_medium(const Hit& hit,
                                                                                 const SurfacePoint& sp,
                                                                                 const WhittedCoeffs& c,
                                                                                 RayCounters& counters) const {
    if constexpr (K.transmission) {
        if (m_contacts && !c.thin && !is_black(c.kt)) [[unlikely]]
            return other_medium(hit, sp, counters);
    }
    return std::nullopt;
}

std::optional<Hit> WhittedIntegrator::covering_surface(const Hit& hit, const SurfacePoint& sp,
                                                       RayCounters& counters) const {
    if (m_covers && m_covers->candidate(object_index(m_view.scene(), hit.geom, hit.inst))) [[unlikely]]
        return opaque_cover(hit, sp, counters);
    return std::nullopt;
}

std::optional<WhittedIntegrator::OtherMedium> WhittedIntegrator::other_medium(const Hit& hit, const SurfacePoint& sp,
                                                                               RayCounters& counters) const {
    const Scene& scene = m_view.scene();
    if (!m_contacts->candidate(object_index(scene, hit.geom, hit.inst))) return std::nullopt;
    ++counters.contact_probe;
    const auto contact = m_contacts->at(sp.p, sp.offset_scale, sp.ng);  // along the hit's outward normal
    if (!contact) return std::nullopt;
    const MaterialFeatures& mf = m_view.analysis().materials[scene.geom_material(contact->hit.geom)];
    const SurfacePoint so = m_view.surface(contact->probe, contact->hit);
    return OtherMedium{mf.varying ? m_view.coefficients(so) : mf.constant, so.p, so.offset_scale};
}

std::optional<Hit> WhittedIntegrator::opaque_cover(const Hit& hit, const SurfacePoint& sp, RayCounters& counters) const {
    Hit cover = m_covers->at(sp.p, sp.offset_scale, sp.ng, counters);
    if (!cover.valid()) return std::nullopt;
    cover.t = hit.t;  // the same ray's hit at the same distance (cone width, absorption)
    return cover;
}

// ---- Rays in, radiance out ----------------------------------------------------------------------

template <KernelFeatures K>
Color WhittedIntegrator::trace(const Ray& ray, RayKind kind, int depth, RayCounters& counters, PrimaryInfo* primary,
                               const RayCone& cone, float weight) const {
    count(counters, kind);
    return shade<K>(ray, m_accel.intersect(ray, kind), depth, counters, primary, cone, weight);
}

void WhittedIntegrator::trace_camera(std::span<const Ray> rays, std::span<Color> radiance, RayCounters& counters,
                                     const RayCone& cone, std::span<PrimaryInfo> primary) const {
    RT_CHECK(radiance.size() == rays.size());
    if (!primary.empty()) RT_CHECK(primary.size() == rays.size());
    (this->*m_trace_camera)(rays, radiance, counters, cone, primary);
}

template <KernelFeatures K>
void WhittedIntegrator::trace_camera(std::span<const Ray> rays, std::span<Color> radiance, RayCounters& counters,
                                     const RayCone& cone, std::span<PrimaryInfo> primary) const {
    auto info = [&](size_t i) { return primary.empty() ? nullptr : &primary[i]; };
    if constexpr (K == kGeneralKernel) {
        // The general kernel stays one closest-hit query per ray: the baseline packets are measured against.
        for (size_t i = 0; i < rays.size(); ++i)
            radiance[i] = trace<K>(rays[i], RayKind::Camera, 0, counters, info(i), cone, 1.f);
    } else {
        // One batch query per chunk (coherent packets in the Embree backend), then the hits are
        // shaded in order, as trace() shades them. Left uninitialised: the query writes every record.
        UninitializedArray<Hit, kCameraBatch> hits;
        for (size_t begin = 0; begin < rays.size(); begin += kCameraBatch) {
            const size_t n = std::min(kCameraBatch, rays.size() - begin);
            m_accel.intersect(rays.subspan(begin, n), RayKind::Camera, hits.first(n));
            counters.camera += n;
            for (size_t j = 0; j < n; ++j)
                radiance[begin + j] = shade<K>(rays[begin + j], hits.at[j], 0, counters, info(begin + j), cone, 1.f);
        }
    }
}

void WhittedIntegrator::probe(const Ray& ray, RayCounters& counters, PrimaryInfo& primary) const {
    ++counters.aov_probe;
    const Hit hit = m_accel.intersect(ray, RayKind::Camera);
    if (!hit.valid()) return;
    const SurfacePoint sp = m_view.surface(ray, hit);
    primary = first_hit(hit, shading_frame(sp, ray.dir).N, m_view.coefficients(sp));  // as shade() reports it
}

WhittedIntegrator::WhittedIntegrator(const SceneView& view, const Accelerator& accel, const IntegratorSettings& settings)
    : m_view(view), m_accel(accel), m_offset(accel.ray_offset()), m_settings(settings),
      m_kernel(select_kernel(view.analysis().features, settings)) {
    // The instantiation for the selected features, chosen once (no per-ray dispatch).
    auto pick = [&]<size_t... I>(std::index_sequence<I...>) {
        ((m_kernel == kKernels[I] ? (void)(m_trace = &WhittedIntegrator::trace<kKernels[I]>,
                                           m_trace_camera = &WhittedIntegrator::trace_camera<kKernels[I]>)
                                  : (void)0),
         ...);
    };
    pick(std::make_index_sequence<std::size(kKernels)>{});
    RT_CHECK(m_trace != nullptr);
    m_environment = view.environment();
    const std::optional<Environment>& env = view.scene().environment;
    if (env && env->ambient_sh && settings.environment_ambient) m_ambient_sh = &*env->ambient_sh;
    if (m_kernel.transmission) {
        m_contacts = DielectricContacts::find(view);
        m_covers = OpaqueCovers::find(view);
    }
}

}  // namespace whitted
