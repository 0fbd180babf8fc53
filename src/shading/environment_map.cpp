// Environment map: MIP lat-long lookups, the median-cut split into lights plus SH9 ambient, the
// residual the lights leave, and the GGX prefilter of both for rough reflections (docs/environment.md).

#include "shading/environment_map.h"

#include <algorithm>
#include <utility>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"
#include "core/fp_mode.h"
#include "core/parallel.h"
#include "shading/sample_sets.h"

namespace whitted {

namespace {

constexpr double kTwoPiD = 2.0 * kPiD;
/// Samples per prefiltered texel (a fixed Hammersley set: every texel sees the same pattern).
constexpr int kPrefilterSamples = 256;
/// Width of each prefiltered level (height = width / 2), per kPrefilterRoughness.
constexpr std::array<int, 4> kPrefilterWidth{128, 64, 32, 32};

/// Solid angle of one texel of row y of a width x height lat-long (exact for the row's band).
double texel_solid_angle(int y, int width, int height) {
    return kTwoPiD / width * (std::cos(kPiD * y / height) - std::cos(kPiD * (y + 1) / height));
}

/// Texel-centre directions and solid angles of a width x height lat-long, from per-row and
/// per-column tables.
class TexelGrid {
public:
    TexelGrid(int width, int height) : m_cos_phi(size_t(width)), m_sin_phi(size_t(width)), m_sin_theta(size_t(height)),
                                       m_cos_theta(size_t(height)), m_solid_angle(size_t(height)) {
        for (int x = 0; x < width; ++x) {
            const double phi = kTwoPiD * ((x + 0.5) / width - 0.5);
            m_cos_phi[size_t(x)] = std::cos(phi), m_sin_phi[size_t(x)] = std::sin(phi);
        }
        for (int y = 0; y < height; ++y) {
            const double theta = kPiD * (y + 0.5) / height;
            m_sin_theta[size_t(y)] = std::sin(theta), m_cos_theta[size_t(y)] = std::cos(theta);
            m_solid_angle[size_t(y)] = texel_solid_angle(y, width, height);
        }
    }
    /// Unit map-local direction of the centre of texel (x, y).
    Vec3d direction(int x, int y) const {
        const double s = m_sin_theta[size_t(y)];
        return {s * m_cos_phi[size_t(x)], m_cos_theta[size_t(y)], s * m_sin_phi[size_t(x)]};
    }
    /// Solid angle of one texel of row y.
    double solid_angle(int y) const { return m_solid_angle[size_t(y)]; }

private:
    std::vector<double> m_cos_phi, m_sin_phi, m_sin_theta, m_cos_theta, m_solid_angle;
};

/// Source texels under destination texel i when `src` texels shrink to `dst`, with their
/// overlap [a, b) in source texel units.
struct Tap {
    int src = 0;
    double a = 0, b = 0;
};
std::vector<std::vector<Tap>> footprints(int src, int dst) {
    std::vector<std::vector<Tap>> out(static_cast<size_t>(dst));
    const double step = double(src) / dst;
    for (int i = 0; i < dst; ++i) {
        const double lo = i * step, hi = (i + 1) * step;
        for (int s = int(std::floor(lo)); s < src && s < hi; ++s) {
            const double a = std::max(lo, double(s)), b = std::min(hi, double(s + 1));
            if (b > a) out[size_t(i)].push_back({s, a, b});
        }
    }
    return out;
}

/// The pole values of a level: the mean of its first and last rows.
void set_poles(EnvironmentMap::Level& level) {
    Vec3d top(0.0), bottom(0.0);
    for (int x = 0; x < level.width; ++x) {
        top += Vec3d(level.texels[size_t(x)]);
        bottom += Vec3d(level.texels[size_t(level.height - 1) * size_t(level.width) + size_t(x)]);
    }
    level.pole_top = Color(top / double(level.width));
    level.pole_bottom = Color(bottom / double(level.width));
}

/// Next MIP level: each texel is the solid-angle weighted mean of the source texels its
/// footprint covers (a 2x2 box for even sizes, overlap-weighted for odd ones).
EnvironmentMap::Level downsample(const EnvironmentMap::Level& src, WorkerPool& pool) {
    EnvironmentMap::Level dst;
    dst.width = std::max(1, src.width / 2);
    dst.height = std::max(1, src.height / 2);
    dst.texels.resize(size_t(dst.width) * size_t(dst.height));
    const auto across = footprints(src.width, dst.width);
    const auto down = footprints(src.height, dst.height);
    // Solid angle of the covered part of each source row (proportional to it), once per row tap.
    std::vector<std::vector<double>> row_weight(down.size());
    for (size_t y = 0; y < down.size(); ++y)
        for (const Tap& ty : down[y])
            row_weight[y].push_back(std::cos(kPiD * ty.a / src.height) - std::cos(kPiD * ty.b / src.height));
    pool.for_each(size_t(dst.height), [&](size_t row, int) {
        const int y = int(row);
        for (int x = 0; x < dst.width; ++x) {
            Vec3d sum(0.0);
            double weight = 0;
            for (size_t k = 0; k < down[size_t(y)].size(); ++k) {
                const Tap& ty = down[size_t(y)][k];
                const double wy = row_weight[size_t(y)][k];
                for (const Tap& tx : across[size_t(x)]) {
                    const double w = wy * (tx.b - tx.a);
                    sum += Vec3d(src.texels[size_t(ty.src) * size_t(src.width) + size_t(tx.src)]) * w;
                    weight += w;
                }
            }
            dst.texels[size_t(y) * size_t(dst.width) + size_t(x)] = Color(weight > 0 ? sum / weight : Vec3d(0.0));
        }
    });
    set_poles(dst);
    return dst;
}

/// MIP pyramid from `base` down to 1 x 1.
std::vector<EnvironmentMap::Level> pyramid(EnvironmentMap::Level base, WorkerPool& pool) {
    std::vector<EnvironmentMap::Level> levels;
    levels.push_back(std::move(base));
    while (levels.back().width > 1 || levels.back().height > 1) levels.push_back(downsample(levels.back(), pool));
    return levels;
}

/// The levels of a pyramid of `count` levels a trilinear lookup at `lod` reads: level k0 alone
/// (level 0 below 0, the last level beyond it), or k0 and k0 + 1 mixed by f.
struct LevelBlend {
    size_t k0 = 0;
    bool two = false;
    float f = 0.f;
};
LevelBlend level_blend(size_t count, float lod) {
    const int last = int(count) - 1;
    if (!(lod > 0.f)) return {0, false, 0.f};
    if (lod >= float(last)) return {size_t(last), false, 0.f};
    const int l0 = int(lod);
    return {size_t(l0), true, lod - float(l0)};
}

/// Trilinear lookup of a pyramid at a map-local direction: bilinear within a level, linear between
/// the two levels around `lod` (level_blend).
Color sample_pyramid(const std::vector<EnvironmentMap::Level>& levels, const Vec3f& map_dir, float lod) {
    const Vec2f uv = latlong_uv(map_dir);
    const LevelBlend b = level_blend(levels.size(), lod);
    const Color c0 = levels[b.k0].bilinear(uv.x, uv.y);
    return b.two ? lerp(c0, levels[b.k0 + 1].bilinear(uv.x, uv.y), b.f) : c0;
}

/// What the extracted lights leave of texel c of luminance lum: scaled down to luminance
/// `threshold` when above it (the hue kept), else c.
Color residual_texel(const Color& c, double lum, double threshold) {
    return lum > threshold ? c * float(threshold / lum) : c;
}

/// A region of the median cut: texels [x0, x1) x [y0, y1) and their energy.
struct Region {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    double energy = 0;
    bool splittable = true;
};

/// Summed-area table of one value per texel (double), queried per rectangle.
class SummedArea {
public:
    SummedArea(int width, int height) : m_width(width), m_sum(size_t(width + 1) * size_t(height + 1), 0.0) {}
    void set_row(int y, const std::vector<double>& values) {
        double run = 0;
        for (int x = 0; x < m_width; ++x) {
            run += values[size_t(x)];
            at(x + 1, y + 1) = at(x + 1, y) + run;
        }
    }
    double rect(int x0, int y0, int x1, int y1) const { return at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0); }
    size_t bytes() const { return m_sum.size() * sizeof(double); }

private:
    double& at(int x, int y) { return m_sum[size_t(y) * size_t(m_width + 1) + size_t(x)]; }
    double at(int x, int y) const { return m_sum[size_t(y) * size_t(m_width + 1) + size_t(x)]; }
    int m_width;
    std::vector<double> m_sum;
};

/// Debevec's (2005) cut of `r` in two along its longer side in angle (the width scaled by the
/// sine of the polar angle at its centre), at the texel boundary nearest the energy median.
/// False when the region is one texel.
bool cut_region(const Region& r, const SummedArea& sat, int width, int height, Region& a, Region& b) {
    const int nx = r.x1 - r.x0, ny = r.y1 - r.y0;
    const double theta = kPiD * 0.5 * (r.y0 + r.y1) / height;
    const double wide = nx * kTwoPiD / width * std::sin(theta), tall = ny * kPiD / height;
    const bool along_x = nx >= 2 && (wide >= tall || ny < 2);
    if (!along_x && ny < 2) return false;
    const int lo = (along_x ? r.x0 : r.y0) + 1, hi = (along_x ? r.x1 : r.y1) - 1;
    auto below = [&](int k) { return along_x ? sat.rect(r.x0, r.y0, k, r.y1) : sat.rect(r.x0, r.y0, r.x1, k); };
    // First boundary whose lower part holds half the energy, or the one before it if closer.
    const double half = 0.5 * r.energy;
    int first = lo, last = hi;
    while (first < last) {
        const int mid = first + (last - first) / 2;
        if (below(mid) >= half) last = mid; else first = mid + 1;
    }
    int k = first;
    if (k > lo && std::fabs(below(k - 1) - half) <= std::fabs(below(k) - half)) --k;
    a = r, b = r;
    (along_x ? a.x1 : a.y1) = k;
    (along_x ? b.x0 : b.y0) = k;
    a.energy = sat.rect(a.x0, a.y0, a.x1, a.y1);
    b.energy = sat.rect(b.x0, b.y0, b.x1, b.y1);
    return true;
}

/// Median cut of the energy in `sat` into at most n regions: whole rounds of Debevec's cut while
/// they fit in n, then the most energetic region next; regions without energy are never cut.
std::vector<Region> median_cut(const SummedArea& sat, int width, int height, int n) {
    std::vector<Region> regions;
    Region all{0, 0, width, height, sat.rect(0, 0, width, height), true};
    if (!(all.energy > 0) || n < 1) return regions;
    regions.push_back(all);
    auto cut = [&](Region& r, std::vector<Region>& out) {
        Region a, b;
        if (r.energy > 0 && r.splittable && cut_region(r, sat, width, height, a, b)) {
            out.push_back(a);
            out.push_back(b);
            return true;
        }
        r.splittable = false;
        out.push_back(r);
        return false;
    };
    // Whole rounds: every region cut once.
    while (regions.size() * 2 <= size_t(n)) {
        std::vector<Region> next;
        bool progress = false;
        for (Region& r : regions) progress = cut(r, next) || progress;
        regions = std::move(next);
        if (!progress) break;
    }
    // Then the most energetic region that can still be cut (the first of equals).
    while (regions.size() < size_t(n)) {
        size_t best = regions.size();
        for (size_t i = 0; i < regions.size(); ++i)
            if (regions[i].splittable && regions[i].energy > 0 && (best == regions.size() || regions[i].energy > regions[best].energy))
                best = i;
        if (best == regions.size()) break;
        std::vector<Region> two;
        if (cut(regions[best], two) && two.size() == 2) {
            regions[best] = two[0];
            regions.insert(regions.begin() + std::ptrdiff_t(best) + 1, two[1]);
        } else {
            regions[best].splittable = false;
        }
    }
    return regions;
}

/// The GGX prefilter of a pyramid, one lat-long per kPrefilterRoughness, by filtered importance
/// sampling (Krivanek & Colbert 2008): a fixed Hammersley set per texel, each sample read from the
/// MIP level whose texel matches its solid angle.
std::vector<EnvironmentMap::Level> prefilter(const std::vector<EnvironmentMap::Level>& source, uint32_t levels,
                                            WorkerPool& pool) {
    const double texel_sr = 4.0 * kPiD / (double(source.front().width) * double(source.front().height));
    std::vector<EnvironmentMap::Level> out;
    struct Row {
        size_t level;
        int y;
    };
    std::vector<Row> rows;
    for (size_t k = 0; k < kPrefilterRoughness.size(); ++k) {
        EnvironmentMap::Level level;
        if ((levels >> k) & 1u) {
            level.width = kPrefilterWidth[k];
            level.height = kPrefilterWidth[k] / 2;
            level.texels.resize(size_t(level.width) * size_t(level.height));
            for (int y = 0; y < level.height; ++y) rows.push_back({k, y});
        }
        out.push_back(std::move(level));
    }
    // The samples' GGX half-vector angles, pdf and MIP level are the same for every texel of a
    // level: computed once per level, then only turned into each texel's frame.
    struct Sample {
        float t, b, n;  // h = t sin_h cos(phi) + b sin_h sin(phi) + n cos_h, in the texel's frame
        float lod;
    };
    struct RowSample {
        float u;        // of the sample's direction, relative to its texel's
        float weight;   // N.L
        // sample_pyramid at the sample's v and lod, its v part done (r0 of level k0, r1 of k0 + 1)
        LevelBlend levels;
        EnvironmentMap::Level::Rows r0, r1;
    };
    std::vector<std::vector<Sample>> samples(kPrefilterRoughness.size());
    for (size_t k = 0; k < kPrefilterRoughness.size(); ++k) {
        if (((levels >> k) & 1u) == 0) continue;
        const float alpha = kPrefilterRoughness[k] * kPrefilterRoughness[k];
        const float a2 = alpha * alpha;
        for (int s = 0; s < kPrefilterSamples; ++s) {
            // GGX half vector (normal = view = n), its reflection l, pdf(l) = D(h) / 4.
            const float xi1 = (float(s) + 0.5f) / float(kPrefilterSamples), xi2 = radical_inverse2(uint32_t(s));
            const Vec3f h = ggx_half_vector(xi1, xi2, alpha);
            const float cos2 = (1.f - xi1) / (1.f + (a2 - 1.f) * xi1);
            const float pdf = ggx_distribution(cos2, a2) * 0.25f;
            const float sample_sr = 1.f / (float(kPrefilterSamples) * pdf);
            const float lod = std::max(0.f, 0.5f * std::log2(sample_sr / float(texel_sr)) + 1.f);
            samples[k].push_back({h.x, h.y, h.z, lod});
        }
    }
    pool.for_each(rows.size(), [&](size_t item, int) {
        EnvironmentMap::Level& level = out[rows[item].level];
        const std::vector<Sample>& pattern = samples[rows[item].level];
        const int y = rows[item].y;
        // The pattern in the frame of the row's first texel, turned into map coordinates once: a
        // texel x columns on is the same frame turned about the polar axis by x texels of
        // longitude (the frame's tangent follows longitude), so its samples are the row's shifted
        // by x / width in u, at the same v, level and weight.
        const float u0 = 0.5f / float(level.width);
        const Vec3f n = latlong_direction(u0, (float(y) + 0.5f) / float(level.height));
        const float phi = (u0 - 0.5f) * 2.f * kPi;
        const Vec3f t(-std::sin(phi), 0.f, std::cos(phi));  // toward increasing longitude
        const Vec3f b = cross(n, t);
        thread_local std::vector<RowSample> row;
        row.clear();
        float weight = 0.f;
        for (const Sample& s : pattern) {
            const Vec3f h = t * s.t + b * s.b + n * s.n;
            const Vec3f l = h * (2.f * s.n) - n;
            const float n_dot_l = dot(n, l);
            if (n_dot_l <= 0.f) continue;
            const Vec2f uv = latlong_uv(l);
            RowSample r{uv.x - u0, n_dot_l, level_blend(source.size(), s.lod), {}, {}};
            r.r0 = source[r.levels.k0].rows_at(uv.y);
            if (r.levels.two) r.r1 = source[r.levels.k0 + 1].rows_at(uv.y);
            row.push_back(r);
            weight += n_dot_l;
        }
        for (int x = 0; x < level.width; ++x) {
            const float shift = (float(x) + 0.5f) / float(level.width);
            Color sum(0.f);
            for (const RowSample& r : row) {
                float u = r.u + shift;
                u -= std::floor(u);  // across the seam
                const LevelBlend& b = r.levels;
                const Color c0 = source[b.k0].along(r.r0, u);
                sum += (b.two ? lerp(c0, source[b.k0 + 1].along(r.r1, u), b.f) : c0) * r.weight;
            }
            level.texels[size_t(y) * size_t(level.width) + size_t(x)] = weight > 0.f ? sum / weight : Color(0.f);
        }
    });
    for (EnvironmentMap::Level& level : out)
        if (!level.texels.empty()) set_poles(level);
    return out;
}

/// The stored level pair prefiltered() blends for roughness r: level 0 alone up to the first
/// stored roughness, else the two levels around r.
std::pair<size_t, size_t> prefilter_pair(float roughness) {
    const float r = std::isfinite(roughness) ? std::clamp(roughness, 0.f, 1.f) : 1.f;
    if (r <= kPrefilterRoughness.front()) return {0, 0};
    size_t k = 1;
    while (k + 1 < kPrefilterRoughness.size() && r > kPrefilterRoughness[k]) ++k;
    return {k - 1, k};
}

}  // namespace

// ---- lat-long parameterisation ----------------------------------------------------------------

namespace {

/// atan(x) for x in [0, 1]: an odd polynomial of degree 11, within 3.3e-6 rad of std::atan (a
/// lat-long texel of a 1024-wide map spans 6e-3 rad), scaled to be pi/4 at x = 1 so that the two
/// octants meeting on a diagonal agree (no step of the lookup there); a fraction of the cost of
/// atan2f and acosf.
float atan_unit(float x) {
    const float x2 = x * x;
    return x * (0.99997938f +
                x2 * (-0.33262417f + x2 * (0.19354387f + x2 * (-0.11643312f + x2 * (0.05265343f + x2 * -0.01172122f)))));
}

/// atan2(y, x) from atan_unit, exact on the axes (0 at +x, pi/2 at +y, pi at -x).
float fast_atan2(float y, float x) {
    const float ax = std::fabs(x), ay = std::fabs(y);
    const float hi = std::max(ax, ay), lo = std::min(ax, ay);
    if (!(hi > 0.f)) return 0.f;
    float a = atan_unit(lo / hi);
    if (ay > ax) a = 0.5f * kPi - a;
    if (x < 0.f) a = kPi - a;
    return y < 0.f ? -a : a;
}

}  // namespace

Vec2f latlong_uv(const Vec3f& d) {
    const float len = length(d);
    if (!(len > 0.f) || !std::isfinite(len)) return {0.5f, 0.5f};
    const float u = 0.5f + fast_atan2(d.z, d.x) / (2.f * kPi);
    const float v = fast_atan2(std::sqrt(d.x * d.x + d.z * d.z), d.y) / kPi;  // acos(d.y / len)
    return {std::clamp(u, 0.f, 1.f), std::clamp(v, 0.f, 1.f)};
}

Vec3f latlong_direction(float u, float v) {
    const float theta = v * kPi, phi = (u - 0.5f) * 2.f * kPi;
    return {std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
}

Color EnvironmentMap::Level::bilinear(float u, float v) const {
    if (!std::isfinite(u)) u = 0.5f;
    if (!std::isfinite(v)) v = 0.5f;
    return along(rows_at(v), u);
}

EnvironmentMap::Level::Rows EnvironmentMap::Level::rows_at(float v) const {
    auto row = [&](int y) { return &texels[size_t(y) * size_t(width)]; };
    Rows r;
    // Rows: within half a texel of a pole, blend into the pole's mean (the same for every u).
    const float y = std::clamp(v, 0.f, 1.f) * float(height) - 0.5f;
    if (y < 0.f) {
        r.a_pole = pole_top;
        r.b = row(0);
        r.f = std::clamp(2.f * (y + 0.5f), 0.f, 1.f);
    } else if (y > float(height - 1)) {
        r.a = row(height - 1);
        r.b_pole = pole_bottom;
        r.f = std::clamp(2.f * (y - float(height - 1)), 0.f, 1.f);
    } else {
        const int y0 = std::min(int(y), height - 1), y1 = std::min(y0 + 1, height - 1);
        r.a = row(y0);
        r.b = row(y1);
        r.f = y - float(y0);
    }
    return r;
}

Color EnvironmentMap::Level::along(const Rows& r, float u) const {
    // Columns wrap around the seam at u = 0 = 1.
    const float x = u * float(width) - 0.5f;
    const float fx0 = std::floor(x);
    const float fx = x - fx0;
    int xa = int(fx0);
    if (xa < 0 || xa >= width) xa = ((xa % width) + width) % width;
    const int xb = xa + 1 == width ? 0 : xa + 1;
    const Color a = r.a ? lerp(r.a[xa], r.a[xb], fx) : r.a_pole;
    const Color b = r.b ? lerp(r.b[xa], r.b[xb], fx) : r.b_pole;
    return lerp(a, b, r.f);
}

// ---- SH9 ----------------------------------------------------------------------------------------

Color EnvironmentLighting::irradiance(const Vec3f& n) const {
    Color e = residual_irradiance(n);
    for (const ExtractedLight& l : lights) e += l.intensity * std::max(0.f, dot(n, l.direction));
    return e;
}

Light to_directional_light(const ExtractedLight& light, const std::string& name) {
    Light out;
    out.name = name;
    out.type = LightType::Directional;
    const float peak = max_component(light.intensity);
    out.intensity = peak;
    out.color = peak > 0.f ? light.intensity / peak : Color(0.f);
    out.direction = Vec3d(-light.direction);
    out.attenuation = Attenuation::None;
    return out;
}

// ---- the map ----------------------------------------------------------------------------------

EnvironmentMap::EnvironmentMap(const Environment& env, int threads) : EnvironmentMap(env, threads, Use::Rendering) {}

uint32_t prefilter_levels_read(float lo, float hi) {
    const size_t first = prefilter_pair(std::isfinite(lo) ? std::min(lo, hi) : lo).first;
    const size_t last = prefilter_pair(std::isfinite(hi) ? std::max(lo, hi) : hi).second;
    uint32_t mask = 0;
    for (size_t k = std::min(first, last); k <= std::max(first, last); ++k) mask |= 1u << k;
    return mask;
}

EnvironmentMap::EnvironmentMap(const Environment& env, int threads, Use use, uint32_t levels) {
    if (!env.image || env.image->width < 1 || env.image->height < 1 ||
        env.image->texels.size() != size_t(env.image->width) * size_t(env.image->height))
        throw Error(fmt::format("environment map '{}' has no texels", env.image ? env.image->name : std::string()));
    const ScopedFlushDenormals ftz;  // the same arithmetic whatever mode the caller runs in
    const EnvironmentImage& image = *env.image;
    m_name = image.name;
    m_visible = env.visible;
    const double angle = double(env.rotation_deg) * kPiD / 180.0;
    m_cos = float(std::cos(angle));
    m_sin = float(std::sin(angle));

    // Every pass below runs over rows in parallel; sums over rows are added up in row order, so
    // the map is the same for any thread count.
    WorkerPool pool(threads);

    // Level 0: the image at its exposure; negative and non-finite texels count as black. With it,
    // each row's sum for the solid-angle weighted mean radiance.
    const float scale = std::exp2(env.exposure_stops);
    Level base;
    base.width = image.width;
    base.height = image.height;
    base.texels.resize(image.texels.size());
    std::vector<Vec3d> row_sums(size_t(base.height), Vec3d(0.0));
    pool.for_each(size_t(base.height), [&](size_t y, int) {
        Vec3d row(0.0);
        for (size_t i = y * size_t(base.width), end = i + size_t(base.width); i < end; ++i) {
            const Color c = image.texels[i] * scale;
            base.texels[i] = {std::isfinite(c.x) ? std::max(c.x, 0.f) : 0.f,
                              std::isfinite(c.y) ? std::max(c.y, 0.f) : 0.f,
                              std::isfinite(c.z) ? std::max(c.z, 0.f) : 0.f};
            row += Vec3d(base.texels[i]);
        }
        row_sums[y] = row;
    });
    set_poles(base);
    m_texel_angle = float(std::max(kTwoPiD / base.width, kPiD / base.height));
    Vec3d sum(0.0);
    for (int y = 0; y < base.height; ++y) sum += row_sums[size_t(y)] * texel_solid_angle(y, base.width, base.height);
    m_mean = Color(sum / (4.0 * kPiD));

    // split() reads level 0 alone: no pyramid, residual or prefilter for it.
    if (use == Use::SplitOnly) {
        m_levels.push_back(std::move(base));
        return;
    }

    // MIP pyramid down to 1 x 1.
    m_levels = pyramid(std::move(base), pool);

    // The residual the extracted lights leave, with its own pyramid only where some texel was
    // extracted (none under an infinite threshold).
    m_threshold = env.extraction_threshold;
    const double threshold = m_threshold;
    if (threshold < kInfinity) {
        const Level& map = m_levels.front();
        Level residual;
        residual.width = map.width;
        residual.height = map.height;
        residual.texels.resize(map.texels.size());
        std::vector<uint8_t> row_extracted(size_t(map.height), 0);
        pool.for_each(size_t(map.height), [&](size_t y, int) {
            for (size_t i = y * size_t(map.width), end = i + size_t(map.width); i < end; ++i) {
                const double lum = luminance(map.texels[i]);
                row_extracted[y] |= uint8_t(lum > threshold);
                residual.texels[i] = residual_texel(map.texels[i], lum, threshold);
            }
        });
        if (std::any_of(row_extracted.begin(), row_extracted.end(), [](uint8_t e) { return e != 0; })) {
            set_poles(residual);
            m_residual = pyramid(std::move(residual), pool);
        }
    }

    // The GGX prefilter of the map and of the residual.
    if ((levels & kAllPrefilterLevels) == 0) return;
    m_prefiltered = prefilter(m_levels, levels, pool);
    if (!m_residual.empty()) m_residual_prefiltered = prefilter(m_residual, levels, pool);
}

Vec3f EnvironmentMap::world_from_map(const Vec3f& d) const {
    return {m_cos * d.x + m_sin * d.z, d.y, -m_sin * d.x + m_cos * d.z};
}

Vec3f EnvironmentMap::map_from_world(const Vec3f& d) const {
    return {m_cos * d.x - m_sin * d.z, d.y, m_sin * d.x + m_cos * d.z};
}

Color EnvironmentMap::radiance(const Vec3f& dir, float cone_angle) const {
    if (!is_finite(dir)) return Color(0.f);
    const float lod = cone_angle > m_texel_angle ? std::log2(cone_angle / m_texel_angle) : 0.f;
    return sample_pyramid(m_levels, map_from_world(dir), lod);
}

Color EnvironmentMap::residual_radiance(const Vec3f& dir, float cone_angle) const {
    if (!is_finite(dir)) return Color(0.f);
    const float lod = cone_angle > m_texel_angle ? std::log2(cone_angle / m_texel_angle) : 0.f;
    return sample_pyramid(residual_levels(), map_from_world(dir), lod);
}

Color EnvironmentMap::prefiltered(const Vec3f& dir, float roughness) const {
    return lookup_prefiltered(m_levels, m_prefiltered, dir, roughness);
}

Color EnvironmentMap::residual_prefiltered(const Vec3f& dir, float roughness) const {
    return m_residual.empty() ? prefiltered(dir, roughness)
                              : lookup_prefiltered(m_residual, m_residual_prefiltered, dir, roughness);
}

Color EnvironmentMap::lookup_prefiltered(const std::vector<Level>& pyramid, const std::vector<Level>& prefiltered,
                                         const Vec3f& dir, float roughness) const {
    RT_CHECK(!prefiltered.empty());  // a Use::SplitOnly map has none
    if (!is_finite(dir)) return Color(0.f);
    const Vec3f d = map_from_world(dir);
    const Vec2f uv = latlong_uv(d);
    const float r = std::isfinite(roughness) ? std::clamp(roughness, 0.f, 1.f) : 1.f;
    const auto [lo, hi] = prefilter_pair(r);
    // A level the analysis left out is a bug (prefilter_levels_read), never a black reflection.
    RT_CHECK(!prefiltered[lo].texels.empty() && !prefiltered[hi].texels.empty());
    if (lo == hi)
        return lerp(pyramid.front().bilinear(uv.x, uv.y), prefiltered.front().bilinear(uv.x, uv.y),
                    r / kPrefilterRoughness.front());
    const float f = (r - kPrefilterRoughness[lo]) / (kPrefilterRoughness[hi] - kPrefilterRoughness[lo]);
    return lerp(prefiltered[lo].bilinear(uv.x, uv.y), prefiltered[hi].bilinear(uv.x, uv.y), std::clamp(f, 0.f, 1.f));
}

EnvironmentLighting EnvironmentMap::split(const SplitSettings& settings) const {
    const ScopedFlushDenormals ftz;
    const Level& base = m_levels.front();
    const int w = base.width, h = base.height;
    EnvironmentLighting out;
    const bool extract = settings.lights > 0;
    const float factor = settings.threshold_factor;
    // Never below the dimmest texel: light common to every direction is a constant, which the
    // ambient holds exactly and point lights only approximate (a uniform map stays all ambient).
    double dimmest = kInfinity;
    for (const Color& c : base.texels) dimmest = std::min(dimmest, luminance(c));
    out.threshold = extract ? float(std::max(factor * luminance(m_mean), dimmest)) : kInfinity;
    const double threshold = out.threshold;

    // Per texel: the excess over the threshold (hue kept) to the extracted map, the rest to the
    // residual. Both are projected on SH9 (solid-angle weighted, texel-centre directions, world
    // space); the extracted one only to correct the lights' error below.
    // A texel's extracted part, recomputed where needed rather than stored for the whole map.
    auto extracted_at = [&](size_t i) {
        const Color c = base.texels[i];
        const double lum = luminance(c);
        return lum > threshold ? c - residual_texel(c, lum, threshold) : Color(0.f);
    };
    SummedArea energy(extract ? w : 0, extract ? h : 0);
    std::array<Vec3d, 9> residual_sh{}, extracted_sh{};
    Vec3d residual_power(0.0);
    const TexelGrid grid(w, h);
    // Rows in parallel, each into its own sums; then added up in row order, so the result is the
    // same for any thread count (and the same as one loop over the rows).
    struct RowSums {
        std::array<Vec3d, 9> residual{}, extracted{};
        Vec3d power{0.0};
        std::vector<double> energy;
    };
    std::vector<RowSums> rows(static_cast<size_t>(h));
    WorkerPool pool(0);
    pool.for_each(size_t(h), [&](size_t row, int) {
        const int y = int(row);
        const double sr = grid.solid_angle(y);
        RowSums& r = rows[row];
        if (extract) r.energy.resize(static_cast<size_t>(w));
        // The sums in locals: stores to the energy row (doubles) would otherwise force every
        // accumulator through memory on every texel.
        std::array<Vec3d, 9> residual_sums{}, extracted_sums{};
        Vec3d power(0.0);
        double* const row_energy = extract ? r.energy.data() : nullptr;
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * size_t(w) + size_t(x);
            const Color c = base.texels[i];
            const double lum = luminance(c);
            const Color residual = residual_texel(c, lum, threshold);
            const std::array<float, 9> basis = sh9_basis(world_from_map(Vec3f(grid.direction(x, y))));
            const Color extracted = extract && lum > threshold ? c - residual : Color(0.f);
            if (extract && lum > threshold)
                for (size_t k = 0; k < 9; ++k) extracted_sums[k] += Vec3d(extracted) * double(basis[k]);
            if (extract) row_energy[x] = luminance(extracted) * sr;
            for (size_t k = 0; k < 9; ++k) residual_sums[k] += Vec3d(residual) * double(basis[k]);
            power += Vec3d(residual);
        }
        r.residual = residual_sums;
        r.extracted = extracted_sums;
        r.power = power;
    });
    for (int y = 0; y < h; ++y) {
        const double sr = grid.solid_angle(y);
        const RowSums& r = rows[size_t(y)];
        for (size_t k = 0; k < 9; ++k) residual_sh[k] += r.residual[k] * sr, extracted_sh[k] += r.extracted[k] * sr;
        residual_power += r.power * sr;
        if (extract) energy.set_row(y, r.energy);
    }
    out.residual_power = Color(residual_power);

    // Debevec's median cut of the extracted energy; each region becomes one light at its energy
    // centroid carrying its power / pi (a Lambertian of albedo kd then receives kd (N.L) I).
    Vec3d extracted_power(0.0);
    const std::vector<Region> regions = extract ? median_cut(energy, w, h, settings.lights) : std::vector<Region>{};
    // Each region's power, energy centroid and solid angle, regions in parallel.
    struct RegionSums {
        Vec3d power{0.0}, centroid{0.0};
        double sr_total = 0;
    };
    std::vector<RegionSums> region_sums(regions.size());
    pool.for_each(regions.size(), [&](size_t item, int) {
        const Region& r = regions[item];
        RegionSums& out_sums = region_sums[item];
        for (int y = r.y0; y < r.y1; ++y) {
            const double sr = grid.solid_angle(y);
            Vec3d row_power(0.0), row_centroid(0.0);
            for (int x = r.x0; x < r.x1; ++x) {
                const Color e = extracted_at(size_t(y) * size_t(w) + size_t(x));
                row_power += Vec3d(e);
                row_centroid += grid.direction(x, y) * luminance(e);
            }
            out_sums.power += row_power * sr;
            out_sums.centroid += row_centroid * sr;
            out_sums.sr_total += sr * (r.x1 - r.x0);
        }
    });
    for (size_t item = 0; item < regions.size(); ++item) {
        const Region& r = regions[item];
        const auto& [power, centroid, sr_total] = region_sums[item];
        if (!(power.x > 0 || power.y > 0 || power.z > 0)) continue;
        ExtractedLight light;
        const Vec3d mid = grid.direction((r.x0 + r.x1) / 2, (r.y0 + r.y1) / 2);
        light.direction = world_from_map(normalize(Vec3f(length(centroid) > 0 ? centroid : mid)));
        light.intensity = Color(power / kPiD);
        light.solid_angle = float(sr_total);
        light.x0 = r.x0, light.y0 = r.y0, light.x1 = r.x1, light.y1 = r.y1;
        out.lights.push_back(light);
        extracted_power += power;
    }
    out.extracted_power = Color(extracted_power);
    std::stable_sort(out.lights.begin(), out.lights.end(), [](const ExtractedLight& a, const ExtractedLight& b) {
        return luminance(a.intensity) > luminance(b.intensity);
    });

    // A light stands for its region only approximately; in bands 0-2 the difference between
    // the region and its light is known (the extracted projection minus the light's, a delta
    // of its power at its direction), so the ambient absorbs it. Band 0 cancels exactly.
    if (settings.correct_ambient)
        for (const ExtractedLight& l : out.lights) {
            const std::array<float, 9> basis = sh9_basis(l.direction);
            for (size_t k = 0; k < 9; ++k) extracted_sh[k] -= Vec3d(l.intensity) * (kPiD * double(basis[k]));
        }
    for (size_t k = 0; k < 9; ++k)
        out.residual_sh[k] = Color(settings.correct_ambient && k > 0 ? residual_sh[k] + extracted_sh[k] : residual_sh[k]);
    return out;
}

Color EnvironmentMap::brute_force_irradiance(const Vec3f& n) const {
    const Level& base = m_levels.front();
    const Vec3d normal(map_from_world(n));
    const TexelGrid grid(base.width, base.height);
    Vec3d sum(0.0);
    for (int y = 0; y < base.height; ++y) {
        Vec3d row(0.0);
        for (int x = 0; x < base.width; ++x) {
            const double c = dot(normal, grid.direction(x, y));
            if (c > 0) row += Vec3d(base.texels[size_t(y) * size_t(base.width) + size_t(x)]) * c;
        }
        sum += row * grid.solid_angle(y);
    }
    return Color(sum / kPiD);
}

size_t EnvironmentMap::bytes() const {
    size_t total = sizeof(*this);
    for (const Level& l : m_levels) total += l.texels.size() * sizeof(Color);
    for (const Level& l : m_residual) total += l.texels.size() * sizeof(Color);
    for (const Level& l : m_prefiltered) total += l.texels.size() * sizeof(Color);
    for (const Level& l : m_residual_prefiltered) total += l.texels.size() * sizeof(Color);
    return total;
}

size_t EnvironmentMap::estimated_bytes(int width, int height) {
    size_t w = size_t(std::max(width, 1)), h = size_t(std::max(height, 1));
    const size_t base = w * h;
    // split(): the extracted texels and the summed-area table of their energy.
    size_t total = sizeof(EnvironmentMap) + base * sizeof(Color) + (w + 1) * (h + 1) * sizeof(double);
    // The pyramid and the residual's, level 0 included.
    for (;;) {
        total += 2 * w * h * sizeof(Color);
        if (w == 1 && h == 1) break;
        w = std::max<size_t>(1, w / 2), h = std::max<size_t>(1, h / 2);
    }
    for (int pw : kPrefilterWidth) total += 2 * size_t(pw) * size_t(pw / 2) * sizeof(Color);
    return total;
}

}  // namespace whitted
