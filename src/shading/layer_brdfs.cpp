// The glTF layer BRDF terms (see layer_brdfs.h). Sheen: Conty Estevez & Kulla 2017, "Production
// Friendly Microfacet Sheen BRDF", as the KHR_materials_sheen implementation notes write it.
// Iridescence: Belcour & Barla 2017, "A Practical Extension to Microfacet Theory for the Modeling of
// Varying Iridescence", as the KHR_materials_iridescence implementation notes and the Khronos
// glTF-Sample-Viewer's evalIridescence() write it.
#include "shading/layer_brdfs.h"

#include <array>
#include <cmath>
#include <atomic>
#include <mutex>
#include <numbers>

#include "shading/optics.h"

namespace whitted {

namespace {

/// x clamped to [lo, hi]; NaN gives lo.
float clamp_to(float x, float lo, float hi) { return x > lo ? (x < hi ? x : hi) : lo; }
float clamp01(float x) { return clamp_to(x, 0.f, 1.f); }
float sq(float x) { return x * x; }
float mix(float a, float b, float t) { return a + (b - a) * t; }

// ---- Sheen ---------------------------------------------------------------------------------------

/// ln Lambda(x) of the sheen visibility: Conty Estevez & Kulla's fit L(x) = a / (1 + b x^c) + d x + e,
/// its coefficients blended between the alpha = 1 and alpha = 0 fits by (1 - alpha)^2.
float sheen_l(float x, float alpha) {
    const float t = sq(1.f - alpha);
    const float a = mix(21.5473f, 25.3245f, t);
    const float b = mix(3.82987f, 3.32435f, t);
    const float c = mix(0.19823f, 0.16801f, t);
    const float d = mix(-1.97760f, -1.27393f, t);
    const float e = mix(-4.32054f, -4.85967f, t);
    return a / (1.f + b * std::pow(x, c)) + d * x + e;
}

/// Lambda(cos) of the sheen visibility; the fit is mirrored about cos = 0.5 (at most e^20.5).
/// l_half = sheen_l(0.5, alpha).
float sheen_lambda(float cos_theta, float alpha, float l_half) {
    return cos_theta < 0.5f ? std::exp(sheen_l(cos_theta, alpha)) : std::exp(2.f * l_half - sheen_l(1.f - cos_theta, alpha));
}
float sheen_lambda(float cos_theta, float alpha) { return sheen_lambda(cos_theta, alpha, sheen_l(0.5f, alpha)); }

/// G / (4 N.L N.V), G = 1 / (1 + Lambda(N.V) + Lambda(N.L)), for cosines already in
/// [kMinSheenCosine, 1] and alpha in [kMinSheenAlpha, 1], given lambda_v = Lambda(N.V).
float sheen_visibility(float cos_l, float cos_v, float lambda_v, float alpha, float l_half) {
    return 1.f / ((1.f + lambda_v + sheen_lambda(cos_l, alpha, l_half)) * (4.f * cos_v * cos_l));
}
float sheen_visibility(float cos_l, float cos_v, float lambda_v, float alpha) {
    return sheen_visibility(cos_l, cos_v, lambda_v, alpha, sheen_l(0.5f, alpha));
}

// The albedo table: kTableCos columns uniform in sqrt(cos_v), kTableRough rows uniform in
// sqrt((s - s0) / (1 - s0)) for sheen roughness s >= s0 = sqrt(kMinSheenAlpha): both axes denser
// toward grazing and low roughness, where E changes fastest. Bilinear lookups are within 2e-3 of the
// integral for cos_v >= 0.1 and within 2e-2 nearer grazing, where at low roughness E climbs steeply
// to the clamp at 1.
constexpr int kTableCos = 48;
constexpr int kTableRough = 32;
using AlbedoTable = std::array<float, kTableCos * kTableRough>;  // [row * kTableCos + column]

/// Sheen roughness at and below which the clamp of alpha to kMinSheenAlpha holds.
float min_sheen_roughness() { return std::sqrt(kMinSheenAlpha); }
/// cos_v of table column i (column 0 is evaluated at kMinSheenCosine, as the visibility is).
double table_cos(int i) { return std::max(std::pow(double(i) / (kTableCos - 1), 2.0), double(kMinSheenCosine)); }
/// Sheen roughness of table row j.
double table_roughness(int j) {
    const double s0 = min_sheen_roughness();
    return s0 + (1.0 - s0) * std::pow(double(j) / (kTableRough - 1), 2.0);
}

/// Gauss-Legendre nodes and weights on [-1, 1] (Newton on the Legendre recurrence).
template <int N>
struct GaussLegendre {
    std::array<double, N> x{}, w{};
    GaussLegendre() {
        for (int i = 0; i < N; ++i) {
            double z = std::cos(std::numbers::pi * (i + 0.75) / (N + 0.5)), dp = 1.0;
            for (int it = 0; it < 100; ++it) {
                double p0 = 1.0, p1 = 0.0;
                for (int k = 1; k <= N; ++k) {
                    const double p2 = p1;
                    p1 = p0;
                    p0 = ((2 * k - 1) * z * p1 - (k - 1) * p2) / k;
                }
                dp = N * (z * p0 - p1) / (z * z - 1.0);
                const double step = p0 / dp;
                z -= step;
                if (std::abs(step) < 1e-15) break;
            }
            x[size_t(i)] = z;
            w[size_t(i)] = 2.0 / ((1.0 - z * z) * dp * dp);
        }
    }
};

/// E(cos_v, alpha) = integral over the hemisphere of D V (N.L) dL, written over half vectors H
/// (dL = 4 (V.H) dH) in spherical coordinates about N: theta_h by Gauss-Legendre on two panels, the
/// second one on the grazing band where D peaks at low alpha; phi_h by Gauss-Legendre over the
/// arc with N.L > 0, doubled by the symmetry about the plane of N and V.
double sheen_albedo_integral(double cos_v, float alpha) {
    static const GaussLegendre<32> gl_theta;
    static const GaussLegendre<16> gl_phi;
    constexpr double kHalfPi = std::numbers::pi / 2, kGrazingBand = 0.4;
    const double sin_v = std::sqrt(std::max(0.0, 1.0 - cos_v * cos_v));
    const float cos_v_vis = clamp_to(float(cos_v), kMinSheenCosine, 1.f);  // as charlie_visibility
    const float lambda_v = sheen_lambda(cos_v_vis, alpha);
    double sum = 0.0;
    for (const auto [lo, hi] : {std::array{0.0, kHalfPi - kGrazingBand}, std::array{kHalfPi - kGrazingBand, kHalfPi}}) {
        const double half_theta = (hi - lo) / 2;
        for (int i = 0; i < 32; ++i) {
            const double theta = lo + (gl_theta.x[size_t(i)] + 1.0) * half_theta;
            const double cos_h = std::cos(theta), sin_h = std::sin(theta);
            // N.L = 2 (V.H) cos_h - cos_v > 0 where cos(phi) > cos_min: the arc [0, phi_max].
            const double den = 2.0 * cos_h * sin_v * sin_h;
            const double num = cos_v * (1.0 - 2.0 * cos_h * cos_h);
            if (den <= 1e-12 && num >= 0.0) continue;
            const double cos_min = den > 1e-12 ? num / den : -1.0;
            if (cos_min >= 1.0) continue;
            const double half_phi = std::acos(std::max(cos_min, -1.0)) / 2;
            const double d = charlie_distribution(float(cos_h), alpha);
            double row = 0.0;
            for (int k = 0; k < 16; ++k) {
                const double phi = (gl_phi.x[size_t(k)] + 1.0) * half_phi;
                const double v_dot_h = sin_v * sin_h * std::cos(phi) + cos_v * cos_h;
                const double n_dot_l = 2.0 * v_dot_h * cos_h - cos_v;
                if (n_dot_l <= 0.0) continue;
                const float cos_l = clamp_to(float(n_dot_l), kMinSheenCosine, 1.f);
                const double vis = sheen_visibility(cos_l, cos_v_vis, lambda_v, alpha);
                row += gl_phi.w[size_t(k)] * vis * n_dot_l * 4.0 * v_dot_h;
            }
            sum += gl_theta.w[size_t(i)] * half_theta * half_phi * d * sin_h * row;
        }
    }
    return 2.0 * sum;
}

/// The albedo table, each row (one sheen roughness) built on first use: a material reads the two
/// rows about its roughness, so a render computes 2 of the 32 rows, not all of them (about 3 ms
/// instead of 50-80 ms of start-up). std::call_once makes the first use thread-safe; later uses
/// read an atomic flag first (libstdc++'s call_once sets up thread-local state on every call, 5 %
/// of a sheen render when each light's albedo lookup went through it).
class SheenAlbedoTable {
public:
    /// Row j (kTableCos values), built if it is not yet.
    const float* row(int j) {
        if (m_ready[size_t(j)].load(std::memory_order_acquire)) return &m_values[size_t(j * kTableCos)];
        std::call_once(m_built[size_t(j)], [&] {
            // The spec's Lambda fit lets E exceed 1 at grazing, low-roughness views: clamp.
            const float alpha = sq(float(table_roughness(j)));
            for (int i = 0; i < kTableCos; ++i)
                m_values[size_t(j * kTableCos + i)] = float(std::clamp(sheen_albedo_integral(table_cos(i), alpha), 0.0, 1.0));
            m_ready[size_t(j)].store(true, std::memory_order_release);
        });
        return &m_values[size_t(j * kTableCos)];
    }

private:
    AlbedoTable m_values{};
    std::array<std::once_flag, kTableRough> m_built;
    std::array<std::atomic<bool>, kTableRough> m_ready{};
};

SheenAlbedoTable& sheen_albedo_table() {
    static SheenAlbedoTable table;
    return table;
}

// ---- Iridescence ---------------------------------------------------------------------------------

/// Normal-incidence reflectance between media of IOR n_t and n_i.
float ior_to_f0(float n_t, float n_i) { return sq((n_t - n_i) / (n_t + n_i)); }

/// Belcour & Barla's evalSensitivity: the Fourier transform of the CIE XYZ matching functions (a
/// Gaussian fit, two lobes for X) at optical path difference opd_nm with phase shift per channel,
/// normalised so the XYZ of OPD 0 and shift 0 are about 1, converted to linear Rec.709 RGB.
Color eval_sensitivity(float opd_nm, const Color& shift) {
    constexpr float kTwoPi = 2.f * kPi;
    const float phase = kTwoPi * opd_nm * 1e-9f;
    constexpr std::array<float, 3> kVal{5.4856e-13f, 4.4201e-13f, 5.2481e-13f};
    constexpr std::array<float, 3> kPos{1.6810e+06f, 1.7953e+06f, 2.2084e+06f};
    constexpr std::array<float, 3> kVar{4.3278e+09f, 9.3046e+09f, 6.6121e+09f};
    Color xyz;
    for (int c = 0; c < 3; ++c)
        xyz[c] = kVal[size_t(c)] * std::sqrt(kTwoPi * kVar[size_t(c)]) * std::cos(kPos[size_t(c)] * phase + shift[c]) *
                 std::exp(-sq(phase) * kVar[size_t(c)]);
    xyz.x += 9.7470e-14f * std::sqrt(kTwoPi * 4.5282e+09f) * std::cos(2.2399e+06f * phase + shift.x) *
             std::exp(-4.5282e+09f * sq(phase));
    xyz = xyz / 1.0685e-7f;
    // XYZ -> linear Rec.709 (D65).
    return {3.2404542f * xyz.x - 1.5371385f * xyz.y - 0.4985314f * xyz.z,
            -0.9692660f * xyz.x + 1.8760108f * xyz.y + 0.0415560f * xyz.z,
            0.0556434f * xyz.x - 0.2040259f * xyz.y + 1.0572252f * xyz.z};
}

}  // namespace

float charlie_distribution(float n_dot_h, float alpha) {
    const float inv_alpha = 1.f / clamp_to(alpha, kMinSheenAlpha, 1.f);
    const float sin2_h = 1.f - sq(clamp01(n_dot_h));
    return (2.f + inv_alpha) * std::pow(sin2_h, 0.5f * inv_alpha) / (2.f * kPi);
}

float charlie_visibility(float n_dot_l, float n_dot_v, float alpha) {
    const float a = clamp_to(alpha, kMinSheenAlpha, 1.f);
    const float cos_l = clamp_to(n_dot_l, kMinSheenCosine, 1.f);
    const float cos_v = clamp_to(n_dot_v, kMinSheenCosine, 1.f);
    return sheen_visibility(cos_l, cos_v, sheen_lambda(cos_v, a), a);
}

namespace {

/// The two table rows about `sheen_roughness` and the weight between them (row coordinate y, the
/// inverse of table_roughness()).
SheenAlbedoRows albedo_rows(float sheen_roughness) {
    const float s0 = min_sheen_roughness();
    const float y = std::sqrt(clamp01((sheen_roughness - s0) / (1.f - s0))) * float(kTableRough - 1);
    const int j = std::min(int(y), kTableRough - 2);
    SheenAlbedoTable& table = sheen_albedo_table();
    return {table.row(j), table.row(j + 1), y - float(j)};
}

/// E(cos) between the rows (column coordinate x, the inverse of table_cos()).
float albedo_between(const SheenAlbedoRows& r, float cos) {
    const float x = std::sqrt(clamp01(cos)) * float(kTableCos - 1);
    const int i = std::min(int(x), kTableCos - 2);
    const float fx = x - float(i);
    return mix(mix(r.lo[i], r.lo[i + 1], fx), mix(r.hi[i], r.hi[i + 1], fx), r.fy);
}

}  // namespace

float sheen_albedo(float cos_v, float sheen_roughness) { return albedo_between(albedo_rows(sheen_roughness), cos_v); }

SheenLobe sheen_lobe(float n_dot_v, float sheen_roughness) {
    SheenLobe lobe;
    lobe.roughness = clamp01(sheen_roughness);
    lobe.alpha = clamp_to(lobe.roughness * lobe.roughness, kMinSheenAlpha, 1.f);
    lobe.cos_v = clamp_to(n_dot_v, kMinSheenCosine, 1.f);
    lobe.l_half = sheen_l(0.5f, lobe.alpha);
    lobe.lambda_v = sheen_lambda(lobe.cos_v, lobe.alpha, lobe.l_half);
    lobe.albedo = albedo_rows(lobe.roughness);
    return lobe;
}

SheenAtLight sheen_at_light(const SheenLobe& lobe, float n_dot_h, float n_dot_l) {
    const float cos_l = clamp_to(n_dot_l, kMinSheenCosine, 1.f);
    const float brdf = charlie_distribution(n_dot_h, lobe.alpha) * sheen_visibility(cos_l, lobe.cos_v, lobe.lambda_v, lobe.alpha, lobe.l_half);
    return {brdf, albedo_between(lobe.albedo, n_dot_l)};
}

Color iridescence_fresnel(float cos_theta1, float film_ior, float thickness_nm, const Color& base_f0) {
    const float cos1 = clamp01(cos_theta1);
    const float thickness = clamp_to(thickness_nm, 0.f, kMaxFilmThicknessNm);
    const Color f0{clamp01(base_f0.x), clamp01(base_f0.y), clamp01(base_f0.z)};
    const Color base = schlick(f0, cos1);

    // The film fades in over the Khronos smoothstep (film IOR -> outside IOR 1 as thickness -> 0).
    // The result is faded too: the code's R123 >= 1e-5 clamp and Schlick's f90 = 1 at the matched
    // interface leave up to ~0.01 of film reflectance at IOR 1, so thickness 0 gives exactly `base`.
    const float t = clamp01(thickness / kFilmFadeNm);
    const float fade = t * t * (3.f - 2.f * t);
    if (fade <= 0.f) return base;
    const float eta2 = mix(1.f, clamp_to(film_ior, 1.f, kMaxFilmIor), fade);

    // Snell's law into the film; no total internal reflection since eta2 >= 1.
    const float sin2_theta2 = sq(1.f / eta2) * (1.f - sq(cos1));
    const float cos2 = std::sqrt(std::max(0.f, 1.f - sin2_theta2));

    // First interface (outside -> film); its phase shift phi12 is 0 as the film is denser, so phi21 = pi.
    const float r12 = schlick(Color(ior_to_f0(eta2, 1.f)), cos1).x;
    const float t121 = 1.f - r12;
    const float phi21 = kPi;

    // Second interface (film -> base), the base IOR recovered from F0 (clamped below 1 as in the
    // Sample Viewer; the README's F0 + 1e-4 would fail at F0 = 1); phase shift pi where the base is less dense.
    Color r23, phi;
    for (int c = 0; c < 3; ++c) {
        const float sqrt_f0 = std::sqrt(std::min(f0[c], 0.9999f));
        const float base_ior = (1.f + sqrt_f0) / (1.f - sqrt_f0);
        r23[c] = schlick(Color(ior_to_f0(base_ior, eta2)), cos2).x;
        phi[c] = phi21 + (base_ior < eta2 ? kPi : 0.f);
    }
    const float opd = 2.f * eta2 * thickness * cos2;  // first-order optical path difference, nm

    // Spectral integration in Fourier space: the DC term C0 = R12 + Rs and the first two pairs of
    // Diracs, C_m = (Rs - T121) r123^m weighting the sensitivity at m OPD.
    Color film, cm, r123;
    for (int c = 0; c < 3; ++c) {
        const float r123_sq = std::clamp(r12 * r23[c], 1e-5f, 0.9999f);
        const float rs = sq(t121) * r23[c] / (1.f - r123_sq);
        r123[c] = std::sqrt(r123_sq);
        film[c] = r12 + rs;
        cm[c] = rs - t121;
    }
    for (int m = 1; m <= 2; ++m) {
        cm *= r123;
        film += cm * eval_sensitivity(float(m) * opd, phi * float(m)) * 2.f;
    }
    for (int c = 0; c < 3; ++c) film[c] = clamp01(film[c]);
    return base + (film - base) * fade;
}

}  // namespace whitted
