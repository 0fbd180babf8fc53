// Texture lookups (glTF 2.0 samplers, KHR_texture_transform) and MIP chain construction.
//
// Wrap and filter rules follow the OpenGL 4.6 specification section 8.14 (texel centres at
// (i + 0.5) / size, MIRRORED_REPEAT index reflection, bilinear weights), which glTF samplers
// reference. Coordinates are reduced to one wrap period before they are scaled to texels so
// huge or negative uv never overflow an int.
#include "shading/texture_sampling.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/error.h"

namespace whitted {

namespace {

using DecodeTable = std::array<float, 256>;

/// sRGB (IEC 61966-2-1) transfer -> linear, per 8-bit code.
const DecodeTable& srgb_table() {
    static const DecodeTable table = [] {
        DecodeTable t{};
        for (int i = 0; i < 256; ++i) {
            const double c = i / 255.0;
            t[size_t(i)] = float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
        }
        return t;
    }();
    return table;
}

/// Unsigned normalised 8-bit -> [0, 1] (exact i / 255, identical to the sRGB table's path).
const DecodeTable& unorm_table() {
    static const DecodeTable table = [] {
        DecodeTable t{};
        for (int i = 0; i < 256; ++i) t[size_t(i)] = float(i / 255.0);
        return t;
    }();
    return table;
}

inline uint8_t linear_to_unorm8(float v) {
    if (!(v > 0.f)) return 0;
    if (v >= 1.f) return 255;
    return uint8_t(std::lround(double(v) * 255.0));
}

/// Small RGBA accumulator (Vec4f has no arithmetic).
struct Rgba {
    float r = 0.f, g = 0.f, b = 0.f, a = 0.f;
    void add(const Rgba& o, float w) { r += o.r * w; g += o.g * w; b += o.b * w; a += o.a * w; }
    Vec4f vec() const { return {r, g, b, a}; }
};

inline Rgba lerp(const Rgba& p, const Rgba& q, float t) {
    return {p.r + (q.r - p.r) * t, p.g + (q.g - p.g) * t, p.b + (q.b - p.b) * t, p.a + (q.a - p.a) * t};
}

/// Largest floats below 1 and 2: a tiny negative u gives u - floor(u) = 1 - tiny, which rounds
/// to 1.0f and would land in the first texel instead of the last.
constexpr float kBelowOne = 0x1.fffffep-1f;
constexpr float kBelowTwo = 0x1.fffffep0f;

/// Reduces a coordinate to one period of the wrap mode: [0, 1) for Repeat, [0, 2) for
/// MirroredRepeat, [0, 1] for ClampToEdge. Non-finite coordinates count as 0.
inline float reduce_coordinate(float u, WrapMode mode) {
    if (!std::isfinite(u)) return 0.f;
    switch (mode) {
        case WrapMode::Repeat: return std::min(u - std::floor(u), kBelowOne);
        case WrapMode::MirroredRepeat: return std::min(u - 2.f * std::floor(0.5f * u), kBelowTwo);
        case WrapMode::ClampToEdge: break;
    }
    return std::clamp(u, 0.f, 1.f);
}

/// Maps the texel index of a reduced coordinate into [0, n) (GL 4.6 table 8.20). Reduction
/// bounds the index to [-1, n] (Repeat, ClampToEdge) or [-1, 2n] (MirroredRepeat), so one
/// conditional add replaces an integer modulo.
inline int wrap_index(int i, int n, WrapMode mode) {
    switch (mode) {
        case WrapMode::Repeat:
            RT_DCHECK(i >= -1 && i <= n);
            return i < 0 ? i + n : (i >= n ? i - n : i);
        case WrapMode::MirroredRepeat: {
            RT_DCHECK(i >= -1 && i <= 2 * n);
            const int period = 2 * n;
            i = i < 0 ? i + period : (i >= period ? i - period : i);
            return i < n ? i : period - 1 - i;
        }
        case WrapMode::ClampToEdge: break;
    }
    return std::clamp(i, 0, n - 1);
}

/// Everything one lookup needs that does not depend on the MIP level.
struct Lookup {
    float u = 0.f, v = 0.f;        ///< reduced coordinates
    WrapMode wrap_s = WrapMode::Repeat, wrap_t = WrapMode::Repeat;
    const DecodeTable* rgb = nullptr;
    const DecodeTable* alpha = nullptr;
};

inline Rgba fetch(const MipLevel& level, int x, int y, const Lookup& q) {
    const uint8_t* p = level.texels.data() + (size_t(y) * size_t(level.width) + size_t(x)) * 4;
    return {(*q.rgb)[p[0]], (*q.rgb)[p[1]], (*q.rgb)[p[2]], (*q.alpha)[p[3]]};
}

Rgba sample_level(const MipLevel& level, FilterMode filter, const Lookup& q) {
    const int w = level.width, h = level.height;
    RT_DCHECK(w > 0 && h > 0 && level.texels.size() == size_t(w) * size_t(h) * 4);

    if (filter == FilterMode::Nearest) {
        const int x = wrap_index(int(std::floor(q.u * float(w))), w, q.wrap_s);
        const int y = wrap_index(int(std::floor(q.v * float(h))), h, q.wrap_t);
        return fetch(level, x, y, q);
    }

    // Bilinear between the four texel centres around the point; texels are decoded first.
    const float fx = q.u * float(w) - 0.5f, fy = q.v * float(h) - 0.5f;
    const float x0f = std::floor(fx), y0f = std::floor(fy);
    const float tx = fx - x0f, ty = fy - y0f;
    const int x0 = int(x0f), y0 = int(y0f);
    const int xa = wrap_index(x0, w, q.wrap_s), xb = wrap_index(x0 + 1, w, q.wrap_s);
    const int ya = wrap_index(y0, h, q.wrap_t), yb = wrap_index(y0 + 1, h, q.wrap_t);
    const Rgba top = lerp(fetch(level, xa, ya, q), fetch(level, xb, ya, q), tx);
    const Rgba bottom = lerp(fetch(level, xa, yb, q), fetch(level, xb, yb, q), tx);
    return lerp(top, bottom, ty);
}

/// The source texels of one destination texel along one axis of a box-filtered reduction.
struct Taps {
    int first = 0;
    int count = 0;
    std::array<float, 4> weight{};
};

/// Box filter footprint of destination texel `x` when n source texels shrink to m: it covers
/// source interval [x n / m, (x + 1) n / m]; each texel is weighted by its overlap (exact
/// integer arithmetic in units of 1/m texel), so even sizes give the plain 2x2 box.
Taps box_taps(int x, int n, int m) {
    Taps t;
    const int64_t lo = int64_t(x) * n, hi = int64_t(x + 1) * n;  // in units of 1/m texel
    t.first = int(lo / m);
    for (int i = t.first; int64_t(i) * m < hi; ++i) {
        const int64_t overlap = std::min(hi, int64_t(i + 1) * m) - std::max(lo, int64_t(i) * m);
        RT_CHECK(t.count < int(t.weight.size()));
        t.weight[size_t(t.count++)] = float(double(overlap) / double(n));
    }
    return t;
}

/// Box-filters `fetch(x, y)` (linear RGBA of an n_w x n_h level) to the next level size.
template <typename Fetch>
std::vector<Rgba> reduce_level(int src_w, int src_h, int dst_w, int dst_h, Fetch&& fetch_src) {
    std::vector<Taps> taps_x(static_cast<size_t>(dst_w)), taps_y(static_cast<size_t>(dst_h));
    for (int x = 0; x < dst_w; ++x) taps_x[size_t(x)] = box_taps(x, src_w, dst_w);
    for (int y = 0; y < dst_h; ++y) taps_y[size_t(y)] = box_taps(y, src_h, dst_h);

    std::vector<Rgba> dst(size_t(dst_w) * size_t(dst_h));
    // One thread: the importer builds the textures' chains in parallel, one texture per task.
    for (int y = 0; y < dst_h; ++y) {
        const Taps& ty = taps_y[size_t(y)];
        Rgba* out = dst.data() + size_t(y) * size_t(dst_w);
        if (src_w == 2 * dst_w && src_h == 2 * dst_h) {
            // Even sizes: the plain 2x2 box, the general loop's operations in its order (weights
            // 1/2 x 1/2), without its tap bookkeeping.
            for (int x = 0; x < dst_w; ++x) {
                Rgba sum;
                sum.add(fetch_src(2 * x, 2 * y), 0.25f);
                sum.add(fetch_src(2 * x + 1, 2 * y), 0.25f);
                sum.add(fetch_src(2 * x, 2 * y + 1), 0.25f);
                sum.add(fetch_src(2 * x + 1, 2 * y + 1), 0.25f);
                out[x] = sum;
            }
            continue;
        }
        for (int x = 0; x < dst_w; ++x) {
            const Taps& tx = taps_x[size_t(x)];
            Rgba sum;
            for (int j = 0; j < ty.count; ++j)
                for (int i = 0; i < tx.count; ++i)
                    sum.add(fetch_src(tx.first + i, ty.first + j), tx.weight[size_t(i)] * ty.weight[size_t(j)]);
            out[x] = sum;
        }
    }
    return dst;
}

}  // namespace

float srgb8_to_linear(uint8_t v) { return srgb_table()[v]; }

uint8_t linear_to_srgb8_formula(float v) {
    if (!(v > 0.f)) return 0;
    if (v >= 1.f) return 255;
    const double l = v;
    const double s = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
    return uint8_t(std::lround(std::clamp(s, 0.0, 1.0) * 255.0));
}

namespace {

/// linear_to_srgb8_formula's codes by table. threshold[k - 1] holds the bits of the smallest float
/// whose code is at least k (k = 1..255; threshold[255] is a sentinel above every input). Positive
/// floats order like their bits, and the formula never decreases, so each is found by bisection on
/// the bits with the formula itself; a value's code is the number of thresholds at or below it.
/// first_code[b] is that number at the start of bucket b (the bits' top 16: 128 buckets per
/// octave), so a lookup steps past at most a threshold or two. The formula's own codes:
/// tests/unit/test_texture_sampling.cpp compares them over a dense sweep.
struct SrgbEncodeTable {
    std::array<uint32_t, 256> threshold{};
    std::vector<uint8_t> first_code;

    SrgbEncodeTable() {
        const uint32_t one = std::bit_cast<uint32_t>(1.f);
        for (uint32_t k = 1; k <= 255; ++k) {
            uint32_t lo = k == 1 ? 0u : threshold[k - 2], hi = one;  // code(lo) < k <= code(hi) = 255
            while (hi - lo > 1) {
                const uint32_t mid = lo + (hi - lo) / 2;
                (linear_to_srgb8_formula(std::bit_cast<float>(mid)) >= k ? hi : lo) = mid;
            }
            threshold[k - 1] = hi;
        }
        threshold[255] = std::numeric_limits<uint32_t>::max();
        first_code.resize((one >> 16) + 1);
        for (size_t b = 0; b < first_code.size(); ++b)
            first_code[b] = uint8_t(std::upper_bound(threshold.begin(), threshold.begin() + 255, uint32_t(b) << 16) -
                                    threshold.begin());
    }

    uint8_t code(float v) const {  // v in (0, 1)
        const uint32_t bits = std::bit_cast<uint32_t>(v);
        uint32_t k = first_code[bits >> 16];
        while (threshold[k] <= bits) ++k;
        return uint8_t(k);
    }
};

}  // namespace

uint8_t linear_to_srgb8(float v) {
    static const SrgbEncodeTable table;
    if (!(v > 0.f)) return 0;
    if (v >= 1.f) return 255;
    return table.code(v);
}

Vec2f apply_texture_transform(const TextureTransform& xf, Vec2f uv) {
    if (xf.identity()) return uv;
    // uv' = T * R * S * uv. The rotation is the one every implementation and the extension's
    // JSON example use (glTF issue #1563 explains why the GLSL listing reads as its transpose):
    // positive angles turn the UVs counter-clockwise as seen in UV space (v pointing down).
    const float su = xf.scale.x * uv.x, sv = xf.scale.y * uv.y;
    const float c = std::cos(xf.rotation), s = std::sin(xf.rotation);
    return {xf.offset.x + c * su + s * sv, xf.offset.y - s * su + c * sv};
}

Vec4f sample_texture(const Texture& texture, Vec2f uv, float lod) {
    if (texture.levels.empty() || texture.levels[0].width <= 0 || texture.levels[0].height <= 0)
        return {1.f, 1.f, 1.f, 1.f};

    Lookup q;
    q.wrap_s = texture.wrap_s;
    q.wrap_t = texture.wrap_t;
    q.u = reduce_coordinate(uv.x, texture.wrap_s);
    q.v = reduce_coordinate(uv.y, texture.wrap_t);
    q.rgb = texture.srgb ? &srgb_table() : &unorm_table();
    q.alpha = &unorm_table();

    // Magnification (and NaN lod): the full-resolution level with the mag filter.
    if (!(lod > 0.f)) return sample_level(texture.levels[0], texture.mag_filter, q).vec();

    // Minification without a chain: level 0 with the min filter.
    const int last = int(texture.levels.size()) - 1;
    if (!texture.use_mips || last == 0) return sample_level(texture.levels[0], texture.min_filter, q).vec();

    // Trilinear: blend the two levels around lod (clamped to the coarsest level).
    const float level = std::min(lod, float(last));
    const int l0 = int(std::floor(level));
    const float t = level - float(l0);
    const Rgba a = sample_level(texture.levels[size_t(l0)], texture.min_filter, q);
    if (l0 >= last || t <= 0.f) return a.vec();
    const Rgba b = sample_level(texture.levels[size_t(l0 + 1)], texture.min_filter, q);
    return lerp(a, b, t).vec();
}

void build_mip_levels(Texture& texture) {
    if (texture.levels.empty()) return;
    texture.levels.resize(1);
    const MipLevel& base = texture.levels[0];
    if (base.width <= 0 || base.height <= 0) return;
    RT_CHECK_EQ(base.texels.size(), size_t(base.width) * size_t(base.height) * 4);

    const DecodeTable& rgb = texture.srgb ? srgb_table() : unorm_table();
    const DecodeTable& alpha = unorm_table();
    auto encode_rgb = [&](float v) { return texture.srgb ? linear_to_srgb8(v) : linear_to_unorm8(v); };

    // Level 1 filters the decoded 8-bit base; later levels filter the previous level's unquantised
    // linear values, so rounding never accumulates down the chain.
    std::vector<Rgba> previous;
    int w = base.width, h = base.height;
    while (w > 1 || h > 1) {
        const int nw = std::max(1, w / 2), nh = std::max(1, h / 2);
        std::vector<Rgba> current;
        if (previous.empty()) {
            const MipLevel& src = texture.levels[0];
            current = reduce_level(w, h, nw, nh, [&](int x, int y) {
                const uint8_t* p = src.texels.data() + (size_t(y) * size_t(w) + size_t(x)) * 4;
                return Rgba{rgb[p[0]], rgb[p[1]], rgb[p[2]], alpha[p[3]]};
            });
        } else {
            current = reduce_level(w, h, nw, nh, [&](int x, int y) { return previous[size_t(y) * size_t(w) + size_t(x)]; });
        }

        // Quantise: sRGB-encode color data, alpha always linear.
        MipLevel level;
        level.width = nw;
        level.height = nh;
        level.texels.resize(size_t(nw) * size_t(nh) * 4);
        for (size_t i = 0; i < current.size(); ++i) {
            level.texels[4 * i + 0] = encode_rgb(current[i].r);
            level.texels[4 * i + 1] = encode_rgb(current[i].g);
            level.texels[4 * i + 2] = encode_rgb(current[i].b);
            level.texels[4 * i + 3] = linear_to_unorm8(current[i].a);
        }
        texture.levels.push_back(std::move(level));
        previous = std::move(current);
        w = nw;
        h = nh;
    }
}

namespace {

/// Mean over [x - w/2, x + w/2] of the square wave that is +1 on even cells [2k, 2k+1) and -1 on
/// odd ones; w <= 0 point-samples it. The integral of the odd-cell indicator is the ramp
/// I(x) = floor(x/2) + 2 max(x/2 - floor(x/2) - 1/2, 0) (pbrt-v3, Checkerboard2DTexture).
double filtered_square_wave(double x, double w) {
    if (!(w > 1e-6)) {
        // +1 on even cells: floor(x) / 2 is an integer (exact: halving an integer-valued double,
        // no fmod call).
        const double half = std::abs(std::floor(x)) * 0.5;
        return half == std::floor(half) ? 1.0 : -1.0;
    }
    if (w >= 2.0) return 0.0;  // the footprint covers whole periods (near enough): the mean
    auto ramp = [](double y) {
        const double h = y / 2.0, f = std::floor(h);
        return f + 2.0 * std::max(h - f - 0.5, 0.0);
    };
    const double odd = (ramp(x + w / 2) - ramp(x - w / 2)) / w;
    return std::clamp(1.0 - 2.0 * odd, -1.0, 1.0);
}

}  // namespace

Color sample_checker(const Checker& c, Vec2f uv, const Vec3f& p, const Vec3f& n, float width) {
    const double inv = 1.0 / double(c.size);
    const double w = std::isfinite(width) && width > 0.f ? double(width) * inv : 0.0;  // footprint in squares
    // The checker is the product of one square wave per axis; a box filter of the product over a
    // separable footprint is the product of the filtered waves, and the fraction of "a" squares
    // is (1 + product) / 2.
    double product = 1.0;
    if (c.world_space) {
        // 3D solid checker, evaluated a small step inside the surface so points on a face lying on
        // a cell boundary all pick the same cell. The footprint lies in the tangent plane: its
        // extent along world axis i is w sqrt(1 - n_i^2) (0 along a face's own normal).
        // The step must also exceed the hit point's own rounding error (a few ulps of its largest
        // coordinate), or far from the origin the point falls on either side of the face at random.
        const float p_max = std::max(std::fabs(p.x), std::max(std::fabs(p.y), std::fabs(p.z)));
        const float step = std::max(1e-4f * c.size, 16.f * p_max * std::numeric_limits<float>::epsilon());
        const Vec3d q = (Vec3d(p) - Vec3d(n) * double(step)) * inv;
        if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) return c.color_a;
        for (int i = 0; i < 3; ++i) {
            // Axis-aligned faces (the common case: floors and walls) need no square root: the
            // factor is exactly 1 along the face and 0 along its normal.
            const double ni = double(n[i]);
            const double along = ni == 0.0 ? 1.0 : std::abs(ni) == 1.0 ? 0.0 : std::sqrt(std::max(0.0, 1.0 - ni * ni));
            product *= filtered_square_wave(q[i], w * along);
        }
    } else {
        const double s = double(uv.x) * inv, t = double(uv.y) * inv;
        if (!std::isfinite(s) || !std::isfinite(t)) return c.color_a;
        product = filtered_square_wave(s, w) * filtered_square_wave(t, w);
    }
    const float frac_a = float(std::clamp(0.5 * (1.0 + product), 0.0, 1.0));
    return c.color_a * frac_a + c.color_b * (1.f - frac_a);
}

}  // namespace whitted
