#include "integrator/whitted_integrator.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <new>
#include <utility>

#include "core/error.h"
#include "core/tail_split.h"
#include "core/uninitialized.h"
#include "integrator/contacts.h"
#include "shading/local_model.h"
#include "shading/optics.h"
#include "shading/sample_sets.h"

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

/// Transmittances along the rays of one point as one batch query of `accel`: ray(k, r), k < m,
/// writes ray k into r and returns true, or returns false where there is none; put(k, t) for each,
/// put(k, none) where there is no ray. Adds the rays traced to `traced`. The rays are written in
/// place in the batch (a Ray built elsewhere and copied in stalled on reading back its own
/// narrower stores).
template <typename MakeRay, typename Put>
void batch_transmittance(const Accelerator& accel, size_t m, MakeRay ray, Put put, const Color& none,
                         uint64_t& traced) {
    thread_local std::vector<Ray> rays;
    thread_local std::vector<Color> through;
    thread_local std::vector<uint32_t> slot;
    rays.resize(m);
    slot.clear();
    for (size_t k = 0; k < m; ++k) {
        if (ray(k, rays[slot.size()])) slot.push_back(uint32_t(k));
        else put(k, none);
    }
    rays.resize(slot.size());
    traced += rays.size();
    through.resize(rays.size());
    accel.transmittance(std::span<const Ray>(rays), std::span<Color>(through));
    for (size_t b = 0; b < rays.size(); ++b) put(slot[b], through[b]);
}

/// Ward's adaptive test ("Adaptive Shadow Testing for Ray Tracing", 1991) over n candidates:
/// potential(j) is what candidate j gives if nothing blocks it (a Color, not negative);
/// test(ids, out) sets out[k] to what arrives through the scene from candidate ids[k]. The
/// candidates of largest potential (ties by index) are tested, as few as leave what the untested
/// ones could still add, times the path weight `weight`, below `min_weight`; the untested then add
/// their potential scaled by the fraction the tested ones let through (per channel), or unscaled
/// when none was tested. Adds everything to `sum` and the untested count to `skipped`; min_weight
/// 0 tests all. Which candidates are tested depends on the potentials alone, so they are tested
/// together, in one call (one batch query of the accelerator). Which they are is found by
/// selection (split_tail), not by sorting them all; the tests and sums run in the order it leaves
/// them in.
template <typename Potential, typename Test>
Color adaptive_test(Color sum, size_t n, Potential potential, Test test, float weight, float min_weight,
                    uint64_t& skipped) {
    // The keys are not negative, so their bits order like their values: one integer per candidate,
    // the key's bits inverted (largest first) above its index.
    thread_local std::vector<uint64_t> order;
    order.resize(n);
    for (size_t j = 0; j < n; ++j) {
        const float m = max_component(potential(j));
        const float key = m > 0.f ? m : 0.f;  // -0 and NaN as 0
        order[j] = uint64_t(~std::bit_cast<uint32_t>(key)) << 32 | uint64_t(j);
    }
    auto candidate = [&](uint64_t key) -> const Color& { return potential(uint32_t(key)); };
    const size_t i = split_tail(
        std::span<uint64_t>(order), candidate,
        [&](const Color& untested) { return !(weight * max_component(untested) >= min_weight); });
    thread_local std::vector<uint32_t> ids;
    thread_local std::vector<Color> through;
    ids.resize(i);
    through.resize(i);
    for (size_t k = 0; k < i; ++k) ids[k] = uint32_t(order[k]);
    test(std::span<const uint32_t>(ids), std::span<Color>(through));
    Color tested(0.f), passed(0.f);
    for (size_t k = 0; k < i; ++k) {
        passed += through[k];
        tested += candidate(order[k]);
    }
    sum += passed;
    if (i == n) return sum;
    skipped += n - i;
    Color untested(0.f);
    for (size_t j = i; j < n; ++j) untested += candidate(order[j]);
    if (i == 0) return sum + untested;  // all of them together below min_weight: unblocked
    const Color let_through(tested.x > 0.f ? passed.x / tested.x : 1.f, tested.y > 0.f ? passed.y / tested.y : 1.f,
                            tested.z > 0.f ? passed.z / tested.z : 1.f);
    return sum + untested * let_through;
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
    // Storage for coefficients evaluated at this hit, left uninitialised (most hits read a
    // material's constant ones); they are constructed in it, not copied in.
    UninitializedArray<WhittedCoeffs, 1> varying_storage;
    WhittedCoeffs& varying = varying_storage.at[0];
    LayerCoeffs layers;
    const LayerCoeffs* layered = nullptr;
    const WhittedCoeffs* coeffs;
    if constexpr (K.layers) {
        if (mf.layered) {
            ::new (static_cast<void*>(&varying))
                WhittedCoeffs(m_view.layered_coefficients(sp, layer_frame(sp, frame), layers));
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
        const Color Ia = ambient_light(s.f.N);
        Color ambient = Ia * c.ka, behind(0.f);
        if constexpr (K.layers)
            if (layered) ambient += layered_ambient(s, behind);
        // The environment's ambient and the roughest glossy terms reach the point only past the scene.
        Color visible(1.f);
        if (!m_occlusion.empty()) {
            // What the terms it scales could give here, whatever the normal: the material's weights
            // times the brightest irradiance of the ambient.
            float stake = max_component(c.ka);
            if (layered) stake += max_component(layers.sheen_ambient);
            if (depth < m_settings.max_depth) {
                if (c.roughness >= kGlossyRayRoughness) stake += max_component(c.kg);
                if (layered && layers.coat_roughness >= kGlossyRayRoughness) stake += layers.coat_kg;
            }
            visible = environment_visibility(s, stake * m_ambient_max, counters);
            // The diffuse ambient also gets back what the occluders reflect (multi-bounce fit).
            ambient *= multibounce_visibility(visible, c.kd);
        }
        if constexpr (K.layers)
            if (layered) ambient += behind;
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
            Color kg_G = glossy<K>(s, c.kg, layered ? layers.glossy_normal : s.f.N, c.roughness, c.n, visible, counters);
            if (layered && layers.coat_kg > 0.f)
                kg_G += glossy<K>(s, Color(layers.coat_kg), layers.Nc, layers.coat_roughness, layers.coat_n, visible,
                                  counters);
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

Color WhittedIntegrator::layered_ambient(const Shading& s, Color& behind) const {
    const LayerCoeffs& l = *s.layers;
    if (!is_black(l.kdt)) behind = ambient_light(-s.f.N) * l.kdt;  // diffuse transmission: from behind
    return is_black(l.sheen_ambient) ? Color(0.f) : ambient_light(s.f.N) * l.sheen_ambient;
}

/// The cells of a fixed grid over the cosine-weighted hemisphere about N (the same pattern at every
/// point, so the image has no noise; SmoothFrame turns it with N), each weighted by the ambient's
/// radiance from its centre (the SH9, clamped at 0) and tested with an occlusion ray through
/// transparent occluders, the brightest first (Ward's adaptive test: the untested ones, together
/// below min_weight, take the tested ones' fraction). A cell whose transmittance differs from a
/// tested neighbour's lies on an occluder's edge and is traced again at its sub-cells (refine,
/// below), where its share is worth min_weight: an edge moves across the image in steps of a
/// sixteenth of a cell.
/// Directions below the geometric surface (where N leans from Ng) count as unblocked: the surface
/// does not shadow its own shading hemisphere. Exactly 1 when no ray is blocked.
Color WhittedIntegrator::environment_visibility(const Shading& s, float stake, RayCounters& counters) const {
    const float worth = s.weight * stake;
    if (!(worth >= m_settings.min_weight)) return Color(1.f);  // too dim to matter: unblocked
    // The budget's n x n cells for a stake of 1 (a white surface under a uniform map of 1), fewer
    // in proportion below: a cell's share of the stake, the step an occluder's edge makes, stays
    // the same. The stake is constant over a constant material, so the grid does not change
    // across it.
    const float wanted = float(m_settings.env_occlusion) * std::min(worth, 1.f);
    const size_t n = std::clamp(size_t(std::ceil(std::sqrt(wanted))), std::min<size_t>(2, m_occlusion.size()),
                                m_occlusion.size());
    const HemisphereGrid& grid = m_occlusion[n - 1];
    struct Cell {
        Color radiance;       // the ambient's radiance from the centre: the cell's weight
        Color through{-1.f};  // transmittance; negative: not tested
    };
    thread_local std::vector<Cell> cells;
    cells.assign(grid.size(), Cell{});
    const SmoothFrame frame(s.f.N);
    const Vec3f org = m_offset.origin(s.f.front ? s.sp.p_shadow : s.sp.p, s.sp.offset_scale, s.f.Ng);
    // The occlusion ray toward a direction of the frame into r; false below the geometric surface.
    auto occlusion_ray = [&](const Vec3f& local, Ray& r) {
        r.org = org;
        r.dir = frame.to_world(local);
        r.tnear = 0.f;
        r.tfar = kInfinity;
        return dot(r.dir, s.f.Ng) > 0.f;
    };
    // Transmittances along the directions local(0..m), one batch query (1 below the surface).
    auto transmittance_along = [&](size_t m, auto local, auto put) {
        batch_transmittance(
            m_accel, m, [&](size_t k, Ray& r) { return occlusion_ray(local(k), r); }, put, Color(1.f),
            counters.occlusion);
    };
    Color total(0.f);
    for (size_t k = 0; k < cells.size(); ++k) {
        const std::array<float, 9> y = sh9_basis(frame.to_world(grid.centres[k]));
        Color L(0.f);
        for (size_t i = 0; i < 9; ++i) L += (*m_ambient_sh)[i] * y[i];
        cells[k].radiance = vmax(L, Color(0.f));
        total += cells[k].radiance;
    }
    if (is_black(total)) return Color(1.f);
    bool blocked = false;
    auto test = [&](std::span<const uint32_t> ids, std::span<Color> out) {
        transmittance_along(
            ids.size(), [&](size_t k) { return grid.centres[ids[k]]; },
            [&](size_t k, const Color& t) {
                cells[ids[k]].through = t;
                if (!(t == Color(1.f))) blocked = true;
            });
        std::fill(out.begin(), out.end(), Color(0.f));  // summed below, after the refinement
    };
    // The weight that turns a cell's radiance into its share of the stake.
    const float scale = worth / max_component(total);
    adaptive_test(Color(0.f), cells.size(), [&](size_t k) -> const Color& { return cells[k].radiance; }, test, scale,
                  m_settings.min_weight, counters.occlusion_skipped_dim);
    if (!blocked) return Color(1.f);

    // Refine the cells on an occluder's edge (compared with their neighbours' first transmittance):
    // the mean of four sub-cells, each again of its four where it differs from a sibling, down to
    // kOcclusionLevels, wherever the cell's share is still worth min_weight.
    const float cell = 1.f / float(grid.n);
    auto differs = [](const Color& a, const Color& b) {
        const Color d = a - b;
        return std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)}) > 1.f / 64.f;
    };
    auto refine = [&](auto& self, float u0, float v0, float size, int level, float share) -> Color {
        const float h = 0.5f * size;
        std::array<Color, 4> t;
        transmittance_along(
            4, [&](size_t c) { return cosine_direction(u0 + h * (float(c % 2) + 0.5f), v0 + h * (float(c / 2) + 0.5f)); },
            [&](size_t c, const Color& x) { t[c] = x; });
        if (level + 1 < kOcclusionLevels && 0.25f * share >= m_settings.min_weight) {
            std::array<bool, 4> edge;
            for (int c = 0; c < 4; ++c) edge[c] = differs(t[c], t[c ^ 1]) || differs(t[c], t[c ^ 2]);
            for (int c = 0; c < 4; ++c)
                if (edge[c]) t[c] = self(self, u0 + h * float(c % 2), v0 + h * float(c / 2), h, level + 1, 0.25f * share);
        }
        return (t[0] + t[1] + t[2] + t[3]) * 0.25f;
    };
    thread_local std::vector<Color> refined;
    refined.assign(cells.size(), Color(-1.f));
    for (size_t k = 0; k < cells.size(); ++k) {
        const Color t = cells[k].through;
        const float cell_worth = scale * max_component(cells[k].radiance);
        if (t.x < 0.f || !(cell_worth >= m_settings.min_weight)) continue;
        bool edge = false;
        for (const int nb : grid.neighbours(int(k)))
            if (nb >= 0 && cells[size_t(nb)].through.x >= 0.f && differs(cells[size_t(nb)].through, t)) edge = true;
        if (edge)
            refined[k] = refine(refine, float(int(k) % grid.n) * cell, float(int(k) / grid.n) * cell, cell, 0,
                                cell_worth);
    }
    Color tested(0.f), passed(0.f), untested(0.f);
    for (size_t k = 0; k < cells.size(); ++k) {
        if (cells[k].through.x < 0.f) {
            untested += cells[k].radiance;
            continue;
        }
        tested += cells[k].radiance;
        passed += cells[k].radiance * (refined[k].x >= 0.f ? refined[k] : cells[k].through);
    }
    auto ratio = [](float a, float t) { return t > 0.f ? std::clamp(a / t, 0.f, 1.f) : 1.f; };
    const Color let_through(ratio(passed.x, tested.x), ratio(passed.y, tested.y), ratio(passed.z, tested.z));
    const Color arrived = passed + untested * let_through;
    return {ratio(arrived.x, total.x), ratio(arrived.y, total.y), ratio(arrived.z, total.z)};
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
        const LightSample* ls;  // the sample (an environment's lights: SceneView's table, no copy)
        Color potential;  // Is fat (kd N.L + ks (N.H)^n): the light's term if nothing shadows it
        bool behind;      // seen through the surface (diffuse transmission)
    };
    thread_local std::vector<Candidate> environment;
    environment.clear();
    auto origin = [&](const Candidate& e) -> const Vec3f& {
        if (!shadow_org) shadow_org = m_offset.origin(s.f.front ? s.sp.p_shadow : s.sp.p, s.sp.offset_scale, s.f.Ng);
        if (e.behind && !back_org) back_org = m_offset.origin(s.sp.p, s.sp.offset_scale, -s.f.Ng);
        return e.behind ? *back_org : *shadow_org;
    };
    auto lit = [&](const Candidate& e, const Color& shadow) {
        if (is_black(shadow)) return Color(0.f);
        // Opaque scenes: the shadow factor is exactly 1 here, and x * 1 == x.
        if constexpr (K.transmission) return e.potential * shadow;
        else return e.potential;
    };
    auto shadowed = [&](const Candidate& e) {
        Ray ray;
        if (!shadow_ray(*e.light, *e.ls, origin(e), ray)) return Color(0.f);
        count(counters, RayKind::Shadow);
        return lit(e, m_accel.transmittance(ray));
    };
    // The tested extracted lights' shadow rays, one batch query (they are known before any is traced).
    auto shadowed_all = [&](std::span<const uint32_t> ids, std::span<Color> out) {
        batch_transmittance(
            m_accel, ids.size(),
            [&](size_t k, Ray& r) {
                const Candidate& e = environment[ids[k]];
                return shadow_ray(*e.light, *e.ls, origin(e), r);
            },
            [&](size_t k, const Color& shadow) { out[k] = lit(environment[ids[k]], shadow); }, Color(0.f),
            counters.shadow);
    };
    // The extracted lights' highlight scale depends on the material alone: once per point where
    // there are such lights (an environment), instead of once per light.
    const float environment_scale = m_view.environment() ? environment_highlight_scale(c.n) : 1.f;
    auto add_light = [&](uint32_t index) {
        const Light& light = m_view.scene().lights[index];
        // Directional lights (every light extracted from an environment) read their sample in
        // place; the others compute it here.
        // (The computed one is returned into place: assigned from a temporary, its copy read back
        // the callee's narrower stores and stalled.)
        const LightSample* cached = m_view.directional_sample(index);
        UninitializedArray<LightSample, 1> computed;
        const LightSample& ls =
            cached ? *cached : *::new (static_cast<void*>(computed.at)) LightSample(sample_light(light, s.sp.p));
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
        const Candidate e{&light, &ls, ls.intensity * term, behind};
        if (!light.from_environment || !cached) {  // (an environment's lights are all directional)
            sum += shadowed(e);
            return;
        }
        // e.ls points into SceneView's table, which outlives the adaptive test below (copying
        // the sample in stalled on reading back its own partial stores: a tenth of this loop's
        // samples).
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

    return adaptive_test(
        sum, environment.size(), [&](size_t j) -> const Color& { return environment[j].potential; },
        shadowed_all, s.weight, m_settings.min_weight, counters.shadow_skipped_dim);
}

bool WhittedIntegrator::shadow_ray(const Light& light, const LightSample& ls, const Vec3f& org, Ray& shadow) {
    shadow.org = org;
    shadow.tnear = 0.f;
    if (light.type == LightType::Directional) {
        shadow.dir = ls.L;
        shadow.tfar = kInfinity;
    } else {
        const Vec3f to_light = Vec3f(light.position) - org;
        const float d = length(to_light);
        if (!(d > 0.f)) return false;
        shadow.dir = to_light / d;
        shadow.tfar = d * (1.f - 1e-5f);
    }
    return true;
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
    if (!transmitted_direction(s.ray.dir, s.f.N, s.f.Ng, eta, s.c.thin, t.dir)) {
        kr += kt;
        return Color(0.f);
    }
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
/// from the residual instead of the map. Without occlusion it sees the environment only; with it,
/// lobes below kGlossyRayRoughness are traced (glossy_rays) and rougher ones scaled by the
/// ambient's visibility at the point.
template <KernelFeatures K>
Color WhittedIntegrator::glossy(const Shading& s, const Color& kg, const Vec3f& N, float roughness, float n,
                                const Color& visible, RayCounters& counters) const {
    if (!m_environment || is_black(kg)) return Color(0.f);
    if (!worth_tracing(s.weight * max_component(kg), counters)) return Color(0.f);
    const Vec3f R = mirror_direction(s.f.V, N, s.f.Ng);
    Color G = m_environment->prefiltered(R, roughness);
    if (m_environment->has_residual()) G = lerp(G, m_environment->residual_prefiltered(R, roughness), highlight_share(n));
    if (m_glossy_rays == 0) return kg * G;
    if (roughness >= kGlossyRayRoughness) return kg * (G * visible);
    return kg * glossy_rays<K>(s, kg, N, roughness, G, counters);
}

/// The lobe's rays: m_glossy_rays for a glossy weight of 1 (path weight times max(kg)), fewer in
/// proportion below (so a dielectric's faint glossy term, or one seen in a reflection, costs one
/// ray, along the mirror direction). Each stands for its N.L-weighted share (the prefilter's
/// weighting); one whose path weight is below min_weight, or that leaves the scene, takes G, so an
/// unobstructed lobe gives exactly G. One that hits takes what it hits as seen through the lobe
/// (seen_in_lobe): a handful of fixed rays cannot resolve sharp detail, so what they find is
/// shaded smoothly, without recursion.
template <KernelFeatures K>
Color WhittedIntegrator::glossy_rays(const Shading& s, const Color& kg, const Vec3f& N, float roughness,
                                     const Color& G, RayCounters& counters) const {
    const float stake = s.weight * max_component(kg);
    const int rays = std::clamp(int(std::ceil(float(m_glossy_rays) * std::min(stake, 1.f))), 1, m_glossy_rays);
    const float alpha = std::max(roughness * roughness, 1e-3f);
    const SmoothFrame frame(N);
    std::array<std::pair<Vec3f, float>, kMaxGlossyRays> lobe;  // direction, N.L
    size_t used = 0;
    float total = 0.f;
    for (int j = 0; j < rays; ++j) {
        Vec3f L = mirror_direction(s.f.V, N, s.f.Ng);
        if (rays > 1) {
            const Vec3f H = frame.to_world(ggx_half_vector((float(j) + 0.5f) / float(rays), radical_inverse2(uint32_t(j)), alpha));
            const float v_h = dot(s.f.V, H);
            if (!(v_h > 0.f)) continue;
            L = normalize(H * (2.f * v_h) - s.f.V);
        }
        const float n_l = dot(N, L);
        if (!(n_l > 0.f) || !(dot(L, s.f.Ng) > 0.f)) continue;  // below the surface: no light from there
        lobe[used++] = {L, n_l};
        total += n_l;
    }
    if (!(total > 0.f)) return G;
    const RayCone cone{s.secondary.width, std::max(s.secondary.spread, 2.f * alpha / std::sqrt(float(used)))};
    Color sum(0.f);
    float missed = 0.f;
    bool hit_any = false;
    for (size_t j = 0; j < used; ++j) {
        const auto& [L, n_l] = lobe[j];
        const float w = stake * (n_l / total);
        if (!worth_tracing(w, counters)) {
            missed += n_l;
            continue;
        }
        const Ray r = spawn_ray(m_offset, s.sp, s.f.Ng, L);
        count(counters, RayKind::Reflection);
        const Hit hit = m_accel.intersect(r, RayKind::Reflection);
        if (!hit.valid()) {
            missed += n_l;
            continue;
        }
        hit_any = true;
        sum += seen_in_lobe(r, hit, cone, roughness) * n_l;
    }
    if (!hit_any) return G;
    return (sum + G * missed) / total;
}

/// A surface met by a glossy ray, shaded as a rough reflection can see it (path regularisation,
/// Kaplanyan & Dachsbacher 2013): its emission, its diffuse response to the environment unshadowed
/// (the ambient's SH9 times ka, the extracted lights' SH9 times kd), its specular and mirror
/// reflection of the map prefiltered at no less than the lobe's roughness, and what it transmits
/// straight through as the map blurred the same way. No shadow, highlight or secondary ray: the
/// sparkle of a neighbour's highlights and mirror images would otherwise show once per glossy ray.
Color WhittedIntegrator::seen_in_lobe(const Ray& ray, const Hit& hit, const RayCone& cone, float roughness) const {
    const SurfacePoint sp = m_view.surface(ray, hit, cone);
    const ShadingFrame f = shading_frame(sp, ray.dir);
    const WhittedCoeffs c = m_view.coefficients(sp);
    const Material& mat = m_view.scene().materials[sp.material];
    if (mat.model == MaterialModel::GltfPbr && mat.unlit) return sanitize(c.emission);
    Color L = c.emission + ambient_light(f.N) * c.ka + sh9_irradiance(m_lights_sh, f.N) * c.kd;
    const Color specular = c.kr + c.kg;
    if (!is_black(specular))
        L += specular * m_environment->prefiltered(mirror_direction(f.V, f.N, f.Ng), std::max(c.roughness, roughness));
    if (!is_black(c.kt)) L += c.kt * m_environment->prefiltered(ray.dir, roughness);
    return sanitize(L);
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
    // `varying` may be uninitialised storage: the value is constructed in it (returned into place).
    auto evaluate = [&]() -> const WhittedCoeffs& {
        return *::new (static_cast<void*>(&varying)) WhittedCoeffs(m_view.coefficients(sp));
    };
    if constexpr (!K.tables) return evaluate();
    else if constexpr (!K.attributes) return mf.constant;
    else return mf.varying ? evaluate() : mf.constant;
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
    if (m_ambient_sh && settings.env_occlusion > 0) {
        const int n = std::max(1, int(std::lround(std::sqrt(double(settings.env_occlusion)))));
        for (int k = 1; k <= n; ++k) m_occlusion.push_back(cosine_grid(k * k));
        // The ambient's brightest irradiance: over a Fibonacci sphere of normals (the SH9 is smooth).
        constexpr int kNormals = 512;
        for (int i = 0; i < kNormals; ++i) {
            const float y = 1.f - 2.f * (float(i) + 0.5f) / float(kNormals), r = std::sqrt(std::max(0.f, 1.f - y * y));
            const float phi = 2.39996323f * float(i);
            m_ambient_max = std::max(m_ambient_max,
                                     max_component(sh9_irradiance(*m_ambient_sh, Vec3f(r * std::cos(phi), y, r * std::sin(phi)))));
        }
    }
    if (m_environment) {
        m_glossy_rays = glossy_ray_count(settings.env_occlusion);
        // The extracted lights as radiance SH9 (each a delta of power pi I at its direction), for
        // the diffuse light of what glossy rays find.
        for (const Light& l : view.scene().lights) {
            if (!l.from_environment) continue;
            const std::array<float, 9> y = sh9_basis(-normalize(Vec3f(l.direction)));
            for (size_t k = 0; k < 9; ++k) m_lights_sh[k] += l.color * (l.intensity * kPi * y[k]);
        }
    }
    if (m_kernel.transmission) {
        m_contacts = DielectricContacts::find(view);
        m_covers = OpaqueCovers::find(view);
    }
}

}  // namespace whitted
