// The glTF layer BRDF terms (shading/layer_brdfs.h): the Charlie sheen of Conty Estevez & Kulla
// 2017 and its albedo table, and the thin-film Fresnel of Belcour & Barla 2017.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "shading/layer_brdfs.h"
#include "shading/optics.h"

namespace whitted {
namespace {

/// Inputs at and beyond every range: zero, one, tiny, huge, negative, infinite, NaN.
const std::vector<float>& edge_values() {
    static const std::vector<float> values{0.f, 1.f, 0.5f, 1e-30f, -1e-30f, 1e-8f, -1e-8f, 1e-3f, -1.f, 2.f,
                                           1e30f, -1e30f, std::numeric_limits<float>::infinity(),
                                           -std::numeric_limits<float>::infinity(),
                                           std::numeric_limits<float>::quiet_NaN()};
    return values;
}

bool finite(const Color& c) { return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z); }

/// Brute-force directional albedo of the sheen BRDF: the integral of D V (N.L) over directions L,
/// midpoint rule in (t, phi) with N.L = t^2 (resolving the steep Lambda near grazing L), over half
/// the hemisphere doubled by symmetry. Independent of the table's quadrature over half vectors.
double brute_force_albedo(double cos_v, double sheen_roughness, int n_t = 1500, int n_phi = 750) {
    const double alpha = std::max(sheen_roughness * sheen_roughness, double(kMinSheenAlpha));
    const double sin_v = std::sqrt(1.0 - cos_v * cos_v);
    double sum = 0.0;
    for (int i = 0; i < n_t; ++i) {
        const double t = (i + 0.5) / n_t, cos_l = t * t, sin_l = std::sqrt(1.0 - cos_l * cos_l);
        const double vis = charlie_visibility(float(cos_l), float(cos_v), float(alpha));
        double row = 0.0;
        for (int k = 0; k < n_phi; ++k) {
            const double phi = (k + 0.5) / n_phi * kPiD;
            // H = normalize(L + V) with V = (sin_v, 0, cos_v), L = (sin_l cos phi, sin_l sin phi, cos_l).
            const double hx = sin_l * std::cos(phi) + sin_v, hy = sin_l * std::sin(phi), hz = cos_l + cos_v;
            const double n_dot_h = hz / std::sqrt(hx * hx + hy * hy + hz * hz);
            row += charlie_distribution(float(n_dot_h), float(alpha));
        }
        sum += row * vis * cos_l * 2.0 * t;  // d(N.L) = 2 t dt
    }
    return 2.0 * sum * (1.0 / n_t) * (kPiD / n_phi);
}

/// The Khronos evalIridescence (KHR_materials_iridescence implementation notes, Sample Viewer's
/// iridescence.glsl) transcribed literally in double precision, outside IOR 1.
std::array<double, 3> khronos_iridescence(double cos1, double eta2_in, double thickness, std::array<double, 3> f0) {
    auto sq = [](double x) { return x * x; };
    auto schlick1 = [](double r0, double c) { return r0 + (1.0 - r0) * std::pow(std::clamp(1.0 - c, 0.0, 1.0), 5.0); };
    const double outside = 1.0;
    const double s = std::clamp(thickness / 0.03, 0.0, 1.0);
    const double eta2 = outside + (eta2_in - outside) * (s * s * (3.0 - 2.0 * s));
    const double cos2_sq = 1.0 - sq(outside / eta2) * (1.0 - sq(cos1));
    if (cos2_sq < 0.0) return {1.0, 1.0, 1.0};
    const double cos2 = std::sqrt(cos2_sq);
    const double r12 = schlick1(sq((eta2 - outside) / (eta2 + outside)), cos1), t121 = 1.0 - r12;
    const double phi12 = eta2 < outside ? kPiD : 0.0, phi21 = kPiD - phi12;
    const double opd = 2.0 * eta2 * thickness * cos2;
    const double val[3] = {5.4856e-13, 4.4201e-13, 5.2481e-13}, pos[3] = {1.6810e+06, 1.7953e+06, 2.2084e+06},
                 var[3] = {4.3278e+09, 9.3046e+09, 6.6121e+09};
    auto sensitivity = [&](double opd_m, const std::array<double, 3>& shift) {
        const double phase = 2.0 * kPiD * opd_m * 1.0e-9;
        double xyz[3];
        for (int c = 0; c < 3; ++c)
            xyz[c] = val[c] * std::sqrt(2.0 * kPiD * var[c]) * std::cos(pos[c] * phase + shift[size_t(c)]) * std::exp(-sq(phase) * var[c]);
        xyz[0] += 9.7470e-14 * std::sqrt(2.0 * kPiD * 4.5282e+09) * std::cos(2.2399e+06 * phase + shift[0]) *
                  std::exp(-4.5282e+09 * sq(phase));
        for (double& x : xyz) x /= 1.0685e-7;
        return std::array<double, 3>{3.2404542 * xyz[0] - 1.5371385 * xyz[1] - 0.4985314 * xyz[2],
                                     -0.9692660 * xyz[0] + 1.8760108 * xyz[1] + 0.0415560 * xyz[2],
                                     0.0556434 * xyz[0] - 0.2040259 * xyz[1] + 1.0572252 * xyz[2]};
    };
    std::array<double, 3> r23{}, phi{}, out{};
    for (int c = 0; c < 3; ++c) {
        const double sqrt_f0 = std::sqrt(std::clamp(f0[size_t(c)], 0.0, 0.9999));
        const double base_ior = (1.0 + sqrt_f0) / (1.0 - sqrt_f0);
        r23[size_t(c)] = schlick1(sq((base_ior - eta2) / (base_ior + eta2)), cos2);
        phi[size_t(c)] = phi21 + (base_ior < eta2 ? kPiD : 0.0);
    }
    const auto s1 = sensitivity(opd, phi);
    const auto s2 = sensitivity(2.0 * opd, {2.0 * phi[0], 2.0 * phi[1], 2.0 * phi[2]});
    for (int c = 0; c < 3; ++c) {
        const double r123 = std::clamp(r12 * r23[size_t(c)], 1e-5, 0.9999);
        const double rs = sq(t121) * r23[size_t(c)] / (1.0 - r123);
        double cm = rs - t121;
        double i = r12 + rs;
        cm *= std::sqrt(r123);
        i += cm * 2.0 * s1[size_t(c)];
        cm *= std::sqrt(r123);
        i += cm * 2.0 * s2[size_t(c)];
        out[size_t(c)] = std::max(i, 0.0);
    }
    return out;
}

// ---- Charlie distribution and visibility ----------------------------------------------------------

TEST(CharlieSheen, DistributionProjectedAreaIsOne) {
    // The integral of D(N.H) (N.H) over the hemisphere, 2 pi * integral_0^1 D(mu) mu dmu, is 1 for a
    // microfacet distribution; for Charlie it is (2 + 1/a) * integral sin^(1/a+1) cos = 1 exactly.
    for (float alpha : {1e-4f, kMinSheenAlpha, 0.04f, 0.09f, 0.25f, 0.5f, 1.f}) {
        constexpr int n = 200000;
        double sum = 0.0;
        for (int i = 0; i < n; ++i) {
            const double mu = (i + 0.5) / n;
            sum += charlie_distribution(float(mu), alpha) * mu;
        }
        EXPECT_NEAR(2.0 * kPiD * sum / n, 1.0, 1e-3) << "alpha " << alpha;
    }
}

TEST(CharlieSheen, DistributionKnownValues) {
    // Grazing half vector: (2 + 1/alpha) / (2 pi); normal half vector: 0.
    EXPECT_NEAR(charlie_distribution(0.f, 1.f), 3.0 / (2.0 * kPiD), 1e-6);
    EXPECT_NEAR(charlie_distribution(0.f, 0.25f), 6.0 / (2.0 * kPiD), 1e-5);
    EXPECT_NEAR(charlie_distribution(0.f, 0.f), (2.0 + 1.0 / kMinSheenAlpha) / (2.0 * kPiD), 1e-4);  // alpha clamped
    EXPECT_EQ(charlie_distribution(1.f, 0.5f), 0.f);
    // alpha = 1: D = 3 sin(theta_h) / (2 pi).
    EXPECT_NEAR(charlie_distribution(0.6f, 1.f), 3.0 * 0.8 / (2.0 * kPiD), 1e-6);
}

TEST(CharlieSheen, VisibilityIsSymmetricAndQuarterAtNormalIncidence) {
    // At N.L = N.V = 1 Lambda is ~1e-8, so G = 1 and V = 1 / 4.
    for (float alpha : {kMinSheenAlpha, 0.3f, 1.f}) EXPECT_NEAR(charlie_visibility(1.f, 1.f, alpha), 0.25f, 1e-6f);
    for (float a : {0.05f, 0.3f, 0.7f, 1.f})
        for (float b : {0.01f, 0.2f, 0.5f, 0.9f}) EXPECT_EQ(charlie_visibility(a, b, 0.4f), charlie_visibility(b, a, 0.4f));
    // Below kMinSheenCosine a cosine acts as kMinSheenCosine.
    EXPECT_EQ(charlie_visibility(0.f, 0.5f, 0.3f), charlie_visibility(kMinSheenCosine, 0.5f, 0.3f));
}

TEST(CharlieSheen, LobeAtLightsMatchesTheFormulas) {
    // sheen_at_light (the lobe's view terms computed once per point) against
    // charlie_distribution x charlie_visibility over the lobe's whole domain: the same up to
    // rounding (relative 1e-5), 0 where sin(theta_h) = 0, and the albedo is the table's.
    double worst = 0.0;
    for (float roughness : {0.f, 0.1f, 0.3f, 0.5f, 0.8f, 1.f})
        for (float n_dot_v : {0.f, 0.01f, 0.3f, 0.5f, 0.7071f, 1.f}) {
            const SheenLobe lobe = sheen_lobe(n_dot_v, roughness);
            for (int i = 0; i <= 64; ++i)
                for (int j = 0; j <= 64; ++j) {
                    const float n_dot_h = float(i) / 64.f, n_dot_l = float(j) / 64.f;
                    const SheenAtLight at = sheen_at_light(lobe, n_dot_h, n_dot_l);
                    const double want = double(charlie_distribution(n_dot_h, lobe.alpha)) *
                                        charlie_visibility(n_dot_l, n_dot_v, lobe.alpha);
                    ASSERT_TRUE(std::isfinite(at.brdf));
                    worst = std::max(worst, std::abs(at.brdf - want) / std::max(want, 1e-30));
                    if (want == 0.0) {
                        EXPECT_EQ(at.brdf, 0.f);  // N.H = 1: sin(theta_h) = 0
                    }
                    EXPECT_EQ(at.albedo_l, sheen_albedo(n_dot_l, roughness));
                }
        }
    EXPECT_LT(worst, 1e-5);
}

// ---- Sheen albedo ------------------------------------------------------------------------------------

TEST(SheenAlbedo, InUnitRangeAndFiniteOverTheDomain) {
    for (int j = 0; j <= 50; ++j)
        for (int i = 0; i <= 100; ++i) {
            const float e = sheen_albedo(i / 100.f, j / 50.f);
            ASSERT_GE(e, 0.f);
            ASSERT_LE(e, 1.f);
        }
}

TEST(SheenAlbedo, MatchesBruteForceIntegral) {
    // (cos_v, sheenRoughness): table lookups (bilinear between nodes) against a fresh integral.
    const std::array<std::array<double, 2>, 7> points{{{0.5, 0.5}, {0.2, 0.8}, {0.9, 1.0}, {0.3, 0.3},
                                                        {0.7, 0.6}, {0.15, 1.0}, {0.15, 0.2}}};
    for (const auto& [cos_v, roughness] : points) {
        const double expected = std::min(1.0, brute_force_albedo(cos_v, roughness));
        EXPECT_NEAR(sheen_albedo(float(cos_v), float(roughness)), expected, 2e-3)
            << "cos_v " << cos_v << " roughness " << roughness;
    }
}

TEST(SheenAlbedo, AgreesWithEnterprisePbrTableAtHighRoughness) {
    // Dassault Systemes' Enterprise PBR Shading Model (2021x, section "Sheen BRDF") publishes E of the
    // same D and Lambda fit as res/Sheen_E.exr (16 x 16 texel centres, x: cos, y: r = glTF alpha), a
    // Monte Carlo estimate stored as half floats (read with `oiiotool --dumpdata`). Its last row,
    // alpha = 15.5 / 16, at cos = (x + 0.5) / 16.
    // (Its rows at low alpha do not follow the glTF formulas, e.g. 0.61 against 1.0 at alpha = 1/32.)
    const float roughness = std::sqrt(15.5f / 16.f);
    const std::array<std::array<float, 2>, 4> row{{{2.5f / 16, 0.6348f}, {4.5f / 16, 0.5044f},
                                                   {8.5f / 16, 0.3391f}, {15.5f / 16, 0.1702f}}};
    for (const auto& [cos_v, e] : row) EXPECT_NEAR(sheen_albedo(cos_v, roughness), e, 1e-2) << "cos_v " << cos_v;
}

TEST(SheenAlbedo, Trends) {
    // Sheen reflects toward grazing: E falls as the view rises (cos_v >= 0.1; nearer grazing the
    // Lambda fit makes E non-monotonic) and grows with roughness for cos_v >= 0.3 (nearer grazing
    // it peaks just below roughness 1: 0.5857 at 0.95 against 0.5842 at 1 for cos_v = 0.2).
    for (int j = 0; j <= 20; ++j) {
        const float r = j / 20.f;
        for (int i = 10; i < 100; ++i) EXPECT_LE(sheen_albedo((i + 1) / 100.f, r), sheen_albedo(i / 100.f, r) + 1e-6f);
    }
    for (int i = 30; i <= 100; ++i)
        for (int j = 0; j < 20; ++j) EXPECT_GE(sheen_albedo(i / 100.f, (j + 1) / 20.f), sheen_albedo(i / 100.f, j / 20.f) - 1e-6f);
    // Smooth fibres scatter nothing back at normal incidence; rough ones about 0.16.
    EXPECT_LT(sheen_albedo(1.f, 0.f), 1e-4f);
    EXPECT_NEAR(sheen_albedo(1.f, 1.f), 0.163f, 5e-3f);
    // Roughness below sqrt(kMinSheenAlpha) acts as sqrt(kMinSheenAlpha).
    EXPECT_EQ(sheen_albedo(0.3f, 0.f), sheen_albedo(0.3f, std::sqrt(kMinSheenAlpha)));
}

// ---- Iridescence -------------------------------------------------------------------------------------

TEST(Iridescence, ThicknessZeroIsBaseSchlick) {
    for (float cos_v : {0.f, 0.1f, 0.3f, 0.5f, 0.8f, 1.f})
        for (const Color& f0 : {Color(0.f), Color(0.04f), Color(0.5f), Color(0.95f, 0.64f, 0.54f)})
            for (float ior : {1.f, 1.3f, 2.f}) {
                const Color f = iridescence_fresnel(cos_v, ior, 0.f, f0), base = schlick(f0, cos_v);
                for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], base[c], 1e-4f) << "cos " << cos_v << " ior " << ior;
            }
}

TEST(Iridescence, MatchesKhronosCodeBeyondTheFade) {
    // From kFilmFadeNm on, the function is the Khronos evalIridescence (clamped to 1). Film IORs
    // equal to the base's (1.5 for F0 0.04) are left out: there the code's phase shift phi23 steps
    // by pi, and float and double round the tie differently.
    for (float cos_v : {0.f, 0.05f, 0.2f, 0.5f, 0.8f, 1.f})
        for (float ior : {1.f, 1.2f, 1.3f, 1.45f, 1.55f, 2.f, 3.f})
            for (float d : {kFilmFadeNm, 0.5f, 10.f, 100.f, 250.f, 400.f, 777.f, 1500.f})
                for (const Color& f0 : {Color(0.04f), Color(0.5f), Color(0.95f, 0.64f, 0.54f), Color(1.f)}) {
                    const Color f = iridescence_fresnel(cos_v, ior, d, f0);
                    const auto k = khronos_iridescence(cos_v, ior, d, {f0.x, f0.y, f0.z});
                    for (int c = 0; c < 3; ++c)
                        EXPECT_NEAR(f[c], std::min(k[size_t(c)], 1.0), 2e-4)
                            << "cos " << cos_v << " ior " << ior << " d " << d << " f0 " << f0[c];
                }
}

TEST(Iridescence, FilmIorOneIsBaseOnlyAtNormalIncidence) {
    // A film with the outside IOR has no interfaces, but the Khronos code does not make it vanish.
    // At normal incidence R12 = 0 and only the R123 >= 1e-5 clamp is left: r123 = 0.0032 keeps the
    // m = 1, 2 terms at (1 - F0) 0.0032 2 |evalSensitivity| (< 2), within 0.012 of F0.
    for (const Color& f0 : {Color(0.f), Color(0.04f), Color(0.5f), Color(0.9f)})
        for (int i = 1; i <= 400; ++i) {
            const Color f = iridescence_fresnel(1.f, 1.f, 5.f * float(i), f0);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], f0[c], 0.012f * (1.f - f0[c]) + 1e-5f);
        }
    // Off normal, Schlick gives the index-matched top interface R12 = (1 - cos)^5 and the code adds
    // it coherently: at cos 0.3 and 1 nm, about 0.5 against Schlick's 0.2 for F0 = 0.04.
    const Color f = iridescence_fresnel(0.3f, 1.f, 1.f, Color(0.04f));
    const float base = schlick(Color(0.04f), 0.3f).x;
    for (int c = 0; c < 3; ++c) EXPECT_GT(f[c], base + 0.25f);
    // At grazing incidence R12 = 1: total reflection, as for the base.
    const Color grazing = iridescence_fresnel(0.f, 1.f, 300.f, Color(0.04f));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(grazing[c], 1.f, 1e-6f);
}

TEST(Iridescence, InUnitRangeOverGrid) {
    for (int ic = 0; ic <= 20; ++ic)
        for (float d : {0.f, 0.01f, 0.02f, 0.03f, 1.f, 10.f, 50.f, 100.f, 200.f, 300.f, 400.f, 500.f, 700.f, 1000.f,
                        2000.f, 1e4f, 1e5f})
            for (float ior : {1.f, 1.1f, 1.3f, 1.5f, 2.f, 2.5f, 3.f, 5.f, 10.f})
                for (const Color& f0 : {Color(0.f), Color(0.02f), Color(0.04f), Color(0.2f), Color(0.5f), Color(0.9f),
                                        Color(1.f), Color(0.95f, 0.64f, 0.54f)}) {
                    const Color f = iridescence_fresnel(ic / 20.f, ior, d, f0);
                    ASSERT_TRUE(finite(f));
                    for (int c = 0; c < 3; ++c) {
                        ASSERT_GE(f[c], 0.f);
                        ASSERT_LE(f[c], 1.f);
                    }
                }
}

TEST(Iridescence, ColouredAtVisibleThicknesses) {
    // Films a few hundred nm thick reflect visibly coloured light at normal incidence: a film of
    // IOR 1.3 on a grey metal (F0 0.5), and of IOR 2 on glass (F0 0.04).
    for (float d : {300.f, 350.f, 400.f, 450.f, 500.f})
        for (const auto& [ior, f0] : {std::pair{1.3f, 0.5f}, std::pair{2.f, 0.04f}}) {
            const Color f = iridescence_fresnel(1.f, ior, d, Color(f0));
            const float spread = std::max({f.x, f.y, f.z}) - std::min({f.x, f.y, f.z});
            EXPECT_GT(spread, 0.05f) << "d " << d << " ior " << ior;
        }
}

TEST(Iridescence, ContinuousInThickness) {
    for (float ior : {1.3f, 2.f, 3.f})
        for (float cos_v : {0.f, 0.1f, 0.2f, 0.5f, 0.8f, 1.f}) {
            // Beyond the fade: 0.25 nm steps up to 2000 nm change no channel by more than 0.01.
            Color prev = iridescence_fresnel(cos_v, ior, kFilmFadeNm, Color(0.04f));
            for (int i = 1; i <= 8000; ++i) {
                const Color f = iridescence_fresnel(cos_v, ior, kFilmFadeNm + 0.25f * float(i), Color(0.04f));
                for (int c = 0; c < 3; ++c) ASSERT_LT(std::abs(f[c] - prev[c]), 0.01f) << "ior " << ior << " step " << i;
                prev = f;
            }
            // The fade from the base Fresnel (0 nm) to the film (0.03 nm) is a steep but continuous
            // ramp: 1e-4 nm steps change no channel by more than 0.05.
            prev = iridescence_fresnel(cos_v, ior, 0.f, Color(0.04f));
            for (int i = 1; i <= 500; ++i) {
                const Color f = iridescence_fresnel(cos_v, ior, 1e-4f * float(i), Color(0.04f));
                for (int c = 0; c < 3; ++c) ASSERT_LT(std::abs(f[c] - prev[c]), 0.05f) << "ior " << ior << " step " << i;
                prev = f;
            }
        }
}

// ---- Edge inputs ---------------------------------------------------------------------------------

TEST(LayerBrdfs, FiniteForEdgeInputs) {
    for (float a : edge_values())
        for (float b : edge_values()) {
            const float d = charlie_distribution(a, b);
            ASSERT_TRUE(std::isfinite(d) && d >= 0.f) << a << " " << b;
            const float e = sheen_albedo(a, b);
            ASSERT_TRUE(e >= 0.f && e <= 1.f) << a << " " << b;
            for (float c : edge_values()) {
                const float v = charlie_visibility(a, b, c);
                ASSERT_TRUE(std::isfinite(v) && v > 0.f) << a << " " << b << " " << c;
                for (const Color& f0 : {Color(0.04f), Color(c), Color(a, b, c)}) {
                    const Color f = iridescence_fresnel(a, b, c, f0);
                    ASSERT_TRUE(finite(f)) << a << " " << b << " " << c;
                    for (int k = 0; k < 3; ++k) ASSERT_TRUE(f[k] >= 0.f && f[k] <= 1.f) << a << " " << b << " " << c;
                }
            }
        }
}

}  // namespace
}  // namespace whitted
