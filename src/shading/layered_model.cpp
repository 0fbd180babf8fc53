// The layered extensions' coefficients and light terms; the formulas are in layered_model.h and
// the reasons in docs/materials.md, "Layers".
#include "shading/layered_model.h"

#include <algorithm>
#include <cmath>

#include "shading/local_model.h"

namespace whitted {

namespace {

/// Normal-incidence reflectance of the clearcoat (ior 1.5), as KHR_materials_clearcoat fixes it.
constexpr float kCoatF0 = 0.04f;

/// highlight_lobe (local_model.h), 0 for N.H <= 0 or NaN.
inline float lobe(float n_dot_h, float e) { return n_dot_h > 0.f ? highlight_lobe(n_dot_h, e) : 0.f; }

/// Ashikhmin & Shirley's (2000) anisotropic Phong lobe: exponent n_t along T, n_b along B.
inline float anisotropic_lobe(const LayerCoeffs& l, const Vec3f& N, const Vec3f& H) {
    const float n_dot_h = dot(N, H);
    const float sin2 = 1.f - n_dot_h * n_dot_h;
    if (!(sin2 > 1e-12f)) return n_dot_h > 0.f ? 1.f : 0.f;  // H on the normal: the lobe's peak
    const float th = dot(l.T, H), bh = dot(l.B, H);
    return lobe(n_dot_h, (l.n_t * th * th + l.n_b * bh * bh) / sin2);
}

}  // namespace

Color dispersion_iors(float ior, float dispersion) {
    const float h = (ior - 1.f) * 0.025f * std::max(dispersion, 0.f);
    return {ior - h, ior, ior + h};
}

WhittedCoeffs map_layered(const Material& material, const PbrSample& sample, const LayerFrame& f,
                          const MappingOptions& options, LayerCoeffs& l) {
    l = LayerCoeffs{};
    l.cos_v = std::clamp(dot(f.N, f.V), 0.f, 1.f);
    WhittedCoeffs c = map_layered_base(material, sample, options, l.cos_v, l.kdt);
    if (material.model != MaterialModel::GltfPbr || material.unlit) return c;

    // KHR_materials_clearcoat: Schlick at the coat normal (the spec's N.V form, not V.H).
    const float clearcoat = saturate(sample.clearcoat);
    l.Nc = f.Nc;
    if (clearcoat > 0.f) {
        const float x = 1.f - std::clamp(dot(f.Nc, f.V), 0.f, 1.f);
        l.coat = clearcoat * (kCoatF0 + (1.f - kCoatF0) * (x * x * x * x * x));
        l.coat_roughness = saturate(sample.clearcoat_roughness);
        l.coat_n = highlight_exponent(l.coat_roughness * l.coat_roughness, options.max_exponent);
        const float fade = mirror_fade(l.coat_roughness, options.mirror_roughness_cutoff);
        l.coat_kr = l.coat * fade;
        l.coat_kg = l.coat * (1.f - fade);
    }
    const float below = 1.f - l.coat;  // what the coat lets through to the layers under it

    // KHR_materials_sheen: the Charlie lobe, and the albedo scaling of the base at the view.
    const Color sheen = saturate(sample.sheen_color);
    if (!is_black(sheen)) {
        l.sheen_lobe = sheen_lobe(l.cos_v, saturate(sample.sheen_roughness));
        l.sheen_max = max_component(sheen);
        const float e = sheen_albedo(l.cos_v, l.sheen_lobe.roughness);
        l.base_v = 1.f - l.sheen_max * e;
        l.sheen = sheen * below;
        l.sheen_ambient = sheen * (below * e);
    }

    // KHR_materials_anisotropy: the direction in the tangent plane, the two exponents, and the
    // bent normal of the glossy lookup (the Khronos sample viewer's, after Filament).
    const float strength = saturate(sample.anisotropy);
    l.glossy_normal = f.N;
    if (strength > 0.f && f.T != Vec3f(0.f)) {
        const Vec2f d = sample.anisotropy_direction;
        Vec3f t = f.T * d.x + f.B * d.y;
        t = normalize(t - f.N * dot(f.N, t));
        if (t != Vec3f(0.f) && is_finite(t)) {
            const float roughness = saturate(sample.roughness);
            const AnisotropicAlpha a = anisotropic_alpha(roughness, strength);
            l.anisotropic = true;
            l.T = t;
            l.B = cross(f.N, t);
            l.n_t = highlight_exponent(a.t, options.max_exponent);
            l.n_b = highlight_exponent(a.b, options.max_exponent);
            // The isotropic exponent of the same solid angle (the lobe's width is ~ 1/sqrt(n + 2)
            // each way): what the environment's split between its lights and its map reads.
            c.n = std::sqrt((l.n_t + 2.f) * (l.n_b + 2.f)) - 2.f;
            const Vec3f across = cross(l.B, f.V);
            const Vec3f aniso_normal = cross(across, l.B);
            const float bend = 1.f - strength * (1.f - roughness);
            const float bend4 = bend * bend * bend * bend;
            const Vec3f bent = normalize(lerp(aniso_normal, f.N, bend4));
            if (bent != Vec3f(0.f) && is_finite(bent) && dot(bent, f.V) > 0.f) l.glossy_normal = bent;
        }
    }

    // KHR_materials_dispersion: refraction splits per channel (the integrator reads it).
    l.dispersion = std::isfinite(material.dispersion) ? std::max(material.dispersion, 0.f) : 0.f;

    // The layers above scale the base: the coat by 1 - w (its emission too), the sheen by base_v.
    const float scale = below * l.base_v;
    c.kd *= scale;
    c.ka *= scale;
    c.ks *= scale;
    c.kr *= scale;
    c.kg *= scale;
    c.kt *= scale;
    c.emission *= below;
    l.kdt *= scale;
    // The extracted lights' highlight scales, once per point rather than once per light.
    l.environment_scale = environment_highlight_scale(c.n);
    l.coat_environment_scale = environment_highlight_scale(l.coat_n);
    return c;
}

Color layered_term(const WhittedCoeffs& c, const LayerCoeffs& l, const Vec3f& N, const Vec3f& L, const Vec3f& V,
                   float n_dot_l, bool environment_light) {
    if (n_dot_l < 0.f) return l.kdt * -n_dot_l;  // diffuse transmission: light from behind
    const Vec3f H = normalize(L + V);
    const float n_dot_h = std::max(0.f, dot(N, H));

    // The base: its diffuse and highlight terms, scaled by the sheen's albedo at L over the one at V.
    Color base = c.kd * n_dot_l;
    const float scale = environment_light ? l.environment_scale : 1.f;
    if (!is_black(c.ks) && scale > 0.f)  // scale 0: the prefiltered map carries this lobe (local_model.h)
        base += c.ks * ((l.anisotropic ? anisotropic_lobe(l, N, H) : lobe(n_dot_h, c.n)) * scale);
    Color term = base;
    if (!is_black(l.sheen)) {
        const SheenAtLight sheen = sheen_at_light(l.sheen_lobe, n_dot_h, n_dot_l);
        const float base_l = 1.f - l.sheen_max * sheen.albedo_l;
        if (base_l < l.base_v) term = base * (l.base_v > 0.f ? base_l / l.base_v : 0.f);
        term += l.sheen * (kPi * sheen.brdf * n_dot_l);
    }

    // The coat's highlight about its own normal.
    const float coat_scale = environment_light ? l.coat_environment_scale : 1.f;
    if (l.coat > 0.f && coat_scale > 0.f && dot(l.Nc, L) > 0.f)
        term += Color(l.coat * lobe(std::max(0.f, dot(l.Nc, H)), l.coat_n) * coat_scale);
    return term;
}

}  // namespace whitted
