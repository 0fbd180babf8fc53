// The path-traced reference of `whitted bench env` (path_reference.h).
#include "benchmarks/path_reference.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "core/error.h"
#include "core/parallel.h"
#include "integrator/camera.h"
#include "integrator/shading_frame.h"
#include "shading/environment_map.h"
#include "shading/material_mapping.h"
#include "shading/optics.h"
#include "shading/sample_sets.h"

namespace whitted::app {

namespace {

/// Below this perceptual roughness the specular lobe is a perfect mirror (alpha < 1e-3).
constexpr float kDeltaRoughness = 0.03f;

/// SplitMix64 (Steele et al. 2014): a stateless-seeded stream of 64-bit values.
struct Rng {
    uint64_t state;
    uint64_t next() {
        uint64_t z = (state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    /// Uniform in [0, 1).
    float uniform() { return float(next() >> 40) * 0x1p-24f; }
};

/// An orthonormal basis about unit n (tangent_frame: Duff et al. 2017).
struct Basis {
    Vec3f t, b, n;
    explicit Basis(const Vec3f& normal) : n(normal) { tangent_frame(n, t, b); }
    Vec3f world(const Vec3f& d) const { return t * d.x + b * d.y + n * d.z; }
};

/// Smith's height-correlated visibility V = G / (4 N.L N.V) for GGX (glTF Appendix B).
float smith_visibility(float nl, float nv, float a2) {
    const float gv = nl * std::sqrt(nv * nv * (1.f - a2) + a2);
    const float gl = nv * std::sqrt(nl * nl * (1.f - a2) + a2);
    const float s = gv + gl;
    return s > 0.f ? 0.5f / s : 0.f;
}

/// The material at one hit, as the path needs it, with its lobes' selection probabilities at
/// this view (in proportion to each lobe's rough weight).
struct Bsdf {
    Color base;           ///< base colour (linear RGB)
    float metallic = 0.f, roughness = 1.f, transmission = 0.f;
    Color f0_dielectric;  ///< KHR_materials_ior / specular
    float ior = 1.5f;
    bool volume = false;
    Vec3f N, V, Ng;       ///< shading and geometric normal and the view, on the viewer's side
    bool front = true;
    float nv = 1.f, a2 = 1.f;
    float p_spec = 0.f, p_diff = 0.f, p_trans = 0.f;

    bool delta_spec() const { return roughness < kDeltaRoughness; }
    /// Whether some lobe is not a delta (light sampling can reach it).
    bool smooth_part() const { return p_diff > 0.f || (p_spec > 0.f && !delta_spec()); }

    /// F at V.H of the specular lobe: the metal's and the dielectric's, mixed by metallic.
    Color fresnel(float vh) const {
        return schlick(base, vh) * metallic + schlick(f0_dielectric, vh) * (1.f - metallic);
    }
    /// Chooses the lobes' probabilities; false when nothing reflects or transmits.
    bool prepare() {
        nv = std::max(dot(N, V), 1e-6f);
        const float a = roughness * roughness;
        a2 = a * a;
        const float dielectric = 1.f - metallic;
        const float fd = max_component(schlick(f0_dielectric, nv));
        const float w_spec = metallic * max_component(schlick(base, nv)) + dielectric * fd;
        const float lum = float(luminance(base));
        const float w_diff = dielectric * (1.f - transmission) * (1.f - fd) * lum;
        const float w_trans = dielectric * transmission * (1.f - fd) * lum;
        const float total = w_spec + w_diff + w_trans;
        if (!(total > 0.f)) return false;
        p_spec = w_spec / total;
        p_diff = w_diff / total;
        p_trans = w_trans / total;
        return true;
    }
    /// f cos of the non-delta lobes (rough specular, diffuse) toward unit L on the reflecting side.
    Color eval(const Vec3f& L) const {
        const float nl = dot(N, L);
        if (!(nl > 0.f) || !(dot(L, Ng) > 0.f)) return Color(0.f);
        const Vec3f H = normalize(L + V);
        const float vh = std::max(dot(V, H), 0.f), nh = std::max(dot(N, H), 0.f);
        Color f(0.f);
        if (!delta_spec()) f += fresnel(vh) * (ggx_distribution(nh * nh, a2) * smith_visibility(nl, nv, a2) * nl);
        const float kd = (1.f - metallic) * (1.f - transmission);
        if (kd > 0.f) f += base * (Color(1.f) - schlick(f0_dielectric, vh)) * (kd * nl / kPi);
        return f;
    }
    /// The density of the non-delta lobes' sampling toward L (their selection probabilities included).
    float pdf(const Vec3f& L) const {
        const float nl = dot(N, L);
        if (!(nl > 0.f)) return 0.f;
        float p = p_diff * nl / kPi;
        if (!delta_spec() && p_spec > 0.f) {
            const Vec3f H = normalize(L + V);
            const float vh = dot(V, H), nh = dot(N, H);
            if (vh > 0.f && nh > 0.f) p += p_spec * ggx_distribution(nh * nh, a2) * nh / (4.f * vh);
        }
        return p;
    }
};

/// Where the path goes next from a surface.
struct Bounce {
    Vec3f dir;
    Color weight;         ///< f cos / pdf (delta lobes: their weight over their probability)
    float pdf = 0.f;      ///< the non-delta lobes' density toward dir; 0 after a delta lobe
    bool through = false;  ///< the direction crosses the surface
};

/// The environment as a distribution of directions: texels in proportion to their luminance
/// (plus 1/1000 of the mean, so no direction the bilinear lookup lights is impossible) times the
/// solid angle of their row (Pharr et al., pbrt 3rd ed., 14.2.4).
class EnvironmentSampler {
public:
    EnvironmentSampler(const EnvironmentImage& image, const EnvironmentMap& map)
        : m_map(map), m_w(image.width), m_h(image.height) {
        double mean = 0.0;
        for (const Color& c : image.texels) mean += luminance(c);
        mean /= double(std::max<size_t>(1, image.texels.size()));
        m_cdf.resize(size_t(m_w + 1) * size_t(m_h));
        m_rows.resize(size_t(m_h) + 1);
        for (int y = 0; y < m_h; ++y) {
            const double sin_theta = std::sin(kPi * (double(y) + 0.5) / double(m_h));
            double* row = &m_cdf[size_t(y) * size_t(m_w + 1)];
            row[0] = 0.0;
            for (int x = 0; x < m_w; ++x)
                row[x + 1] = row[x] + (luminance(image.at(x, y)) + 1e-3 * mean + 1e-30) * sin_theta;
            m_rows[size_t(y) + 1] = m_rows[size_t(y)] + row[m_w];
        }
    }
    /// A direction (world) and its density per steradian: a texel by its weight, a point
    /// uniform in (u, v) within it.
    Vec3f sample(float u0, float u1, float u2, float u3, float& pdf) const {
        const int y = pick(m_rows.data(), m_h, double(u0) * m_rows.back());
        const double* row = &m_cdf[size_t(y) * size_t(m_w + 1)];
        const int x = pick(row, m_w, double(u1) * row[m_w]);
        const float u = (float(x) + u2) / float(m_w), v = (float(y) + u3) / float(m_h);
        pdf = density(x, y, v);
        return m_map.world_from_map(latlong_direction(u, v));
    }
    /// The density of sample() toward world direction d.
    float pdf(const Vec3f& d) const {
        const Vec2f uv = latlong_uv(m_map.map_from_world(d));
        const int x = std::clamp(int(uv.x * float(m_w)), 0, m_w - 1), y = std::clamp(int(uv.y * float(m_h)), 0, m_h - 1);
        return density(x, y, uv.y);
    }

private:
    /// The first index i in [0, n) with cdf[i + 1] > target.
    static int pick(const double* cdf, int n, double target) {
        const double* it = std::upper_bound(cdf + 1, cdf + n + 1, target);
        return std::clamp(int(it - (cdf + 1)), 0, n - 1);
    }
    /// The texel's probability over the solid angle per unit (u, v) at row position v: texels
    /// are uniform in (u, v), and d(omega) = 2 pi^2 sin(pi v) du dv.
    float density(int x, int y, float v) const {
        const double* row = &m_cdf[size_t(y) * size_t(m_w + 1)];
        const double p = (row[x + 1] - row[x]) / m_rows.back();
        const double sin_theta = std::sin(kPi * double(v));
        if (!(sin_theta > 0.0)) return 0.f;
        return float(p * double(m_w) * double(m_h) / (2.0 * kPi * kPi * sin_theta));
    }
    const EnvironmentMap& m_map;
    int m_w, m_h;
    std::vector<double> m_cdf;   ///< per row, the running sum over its texels (width + 1 values)
    std::vector<double> m_rows;  ///< running sum over the rows' totals (height + 1 values)
};

/// The power heuristic (beta 2) of density a against b.
float power_heuristic(float a, float b) {
    const float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.f ? a2 / (a2 + b2) : 0.f;
}

class PathTracer {
public:
    PathTracer(const Renderer& r, const PathSettings& s)
        : m_view(r.view()), m_accel(r.accelerator()), m_offset(r.accelerator().ray_offset()),
          m_env(*r.view().environment()), m_settings(s),
          m_light(*r.view().scene().environment->image, *r.view().environment()) {}

    /// Radiance along one camera ray: BSDF sampling and environment sampling combined by
    /// multiple importance sampling (Veach 1997), one light sample per non-delta vertex.
    Color radiance(Ray ray, Rng& rng, uint64_t& segments) const {
        Color L(0.f), beta(1.f);
        RayKind kind = RayKind::Camera;
        float bsdf_pdf = 0.f;  // the last bounce's non-delta density; 0: camera ray or a delta lobe
        for (int bounce = 0; bounce < m_settings.max_bounces; ++bounce) {
            ++segments;
            const Hit hit = m_accel.intersect(ray, kind);
            if (!hit.valid()) {
                const float w = bsdf_pdf > 0.f ? power_heuristic(bsdf_pdf, m_light.pdf(ray.dir)) : 1.f;
                return L + beta * m_env.radiance(ray.dir) * w;
            }
            const SurfacePoint sp = m_view.surface(ray, hit);
            const ShadingFrame f = shading_frame(sp, ray.dir);
            const Material& mat = m_view.scene().materials[sp.material];
            const PbrSample in = m_view.material_inputs(mat, sp);
            if (mat.unlit) return L + beta * Color(in.base_color.x, in.base_color.y, in.base_color.z);
            L += beta * in.emissive;
            // BLEND coverage: the path passes the surface with probability 1 - alpha.
            if (mat.alpha_mode == AlphaMode::Blend && rng.uniform() >= in.base_color.w) {
                ray = spawn_ray(m_offset, sp, -f.Ng, ray.dir);
                bsdf_pdf = 0.f;  // light sampling treats the surface as blocking: this path alone finds what is behind
                continue;
            }
            Bsdf b;
            b.base = Color(in.base_color.x, in.base_color.y, in.base_color.z);
            b.metallic = std::clamp(in.metallic, 0.f, 1.f);
            b.roughness = std::clamp(in.roughness, 0.f, 1.f);
            b.transmission = std::clamp(in.transmission, 0.f, 1.f);
            b.ior = mat.ior;
            b.f0_dielectric = vmin(Color(ior_to_f0(mat.ior)) * in.specular_color, Color(1.f)) * in.specular;
            b.volume = mat.has_volume && mat.thickness > 0.f;
            b.N = f.N;
            b.V = f.V;
            b.Ng = f.Ng;
            b.front = f.front;
            if (!b.prepare()) return L;

            if (b.smooth_part()) L += beta * light_sample(b, sp, rng, segments);
            Bounce next;
            if (!sample(b, rng, next)) return L;
            beta *= next.weight;
            if (!is_finite(beta) || is_black(beta)) return L;
            bsdf_pdf = next.pdf;
            ray = spawn_ray(m_offset, sp, next.through ? -f.Ng : f.Ng, next.dir);
            kind = next.through ? RayKind::Refraction : RayKind::Reflection;
            // Russian roulette after the third bounce, by the path's throughput.
            if (bounce >= 3) {
                const float q = std::min(0.95f, max_component(beta));
                if (rng.uniform() >= q) return L;
                beta = beta / q;
            }
        }
        return L;
    }

private:
    /// One direction from the environment's distribution, its light through the non-delta lobes
    /// if nothing at all is in the way (a transmissive surface blocks it: light through one is
    /// found by the BSDF's delta lobes, weighted 1), MIS-weighted against the BSDF's density.
    Color light_sample(const Bsdf& b, const SurfacePoint& sp, Rng& rng, uint64_t& segments) const {
        float pdf = 0.f;
        const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
        const Vec3f L = m_light.sample(u0, u1, u2, u3, pdf);
        if (!(pdf > 0.f)) return Color(0.f);
        const Color f = b.eval(L);
        if (is_black(f)) return Color(0.f);
        const Ray shadow = spawn_ray(m_offset, sp, b.Ng, L);
        ++segments;
        if (!(m_accel.transmittance(shadow) == Color(1.f))) return Color(0.f);
        // The weight from pdf(L), the function the BSDF's side reads (its texel lookup may round
        // a direction on a texel's edge into the neighbour), so the two weights sum to 1.
        return f * m_env.radiance(L) * (power_heuristic(m_light.pdf(L), b.pdf(L)) / pdf);
    }

    /// Picks one lobe (specular, diffuse, transmission) by the probabilities prepare() chose and
    /// samples a direction from it. A non-delta direction is weighted by all non-delta lobes
    /// (f cos over their mixture density), a delta one by its own weight over its probability.
    /// False: the path ends (a direction under the geometric surface).
    bool sample(const Bsdf& b, Rng& rng, Bounce& out) const {
        const Vec3f& N = b.N;
        const Vec3f& V = b.V;
        const float u = rng.uniform();
        const float u1 = rng.uniform(), u2 = rng.uniform();
        const Basis basis(N);
        out.through = false;
        out.pdf = 0.f;
        if (u < b.p_spec && b.delta_spec()) {
            out.dir = reflect(V, N);
            out.weight = b.fresnel(b.nv) / b.p_spec;
        } else if (u < b.p_spec + b.p_diff) {
            if (u < b.p_spec) {
                // GGX half vector by D(h) N.H, reflected about it.
                const Vec3f h = basis.world(ggx_half_vector(u1, u2, b.roughness * b.roughness));
                if (!(dot(V, h) > 0.f)) return false;
                out.dir = reflect(V, h);
            } else {
                out.dir = basis.world(cosine_direction(u1, u2));  // cosine-weighted
            }
            out.pdf = b.pdf(out.dir);
            if (!(out.pdf > 0.f)) return false;
            out.weight = b.eval(out.dir) / out.pdf;
        } else {
            if (!(b.p_trans > 0.f)) return false;
            const Color keep = Color(1.f) - schlick(b.f0_dielectric, b.nv);
            out.weight = b.base * keep * ((1.f - b.metallic) * b.transmission / b.p_trans);
            out.through = true;
            out.dir = -V;
            if (b.volume) {
                // Snell at the smooth interface; total internal reflection sends it back.
                const float eta = b.front ? 1.f / b.ior : b.ior;
                if (const auto t = refract(-V, N, eta)) {
                    out.dir = *t;
                } else {
                    out.dir = reflect(V, N);
                    out.through = false;
                }
            }
        }
        // Reflected directions under the geometric surface (a shading normal's artefact) end the path.
        if (!out.through && dot(out.dir, b.Ng) <= 0.f) return false;
        if (out.through && dot(out.dir, b.Ng) >= 0.f) return false;
        return true;
    }

    const SceneView& m_view;
    const Accelerator& m_accel;
    RayOffsetPolicy m_offset;
    const EnvironmentMap& m_env;
    PathSettings m_settings;
    EnvironmentSampler m_light;
};

}  // namespace

std::string path_trace_refusal(const Renderer& renderer) {
    const Scene& scene = renderer.view().scene();
    if (!renderer.view().environment())
        return "the scene has no environment (it is meant for environment-lit scenes)";
    const auto punctual = std::count_if(scene.lights.begin(), scene.lights.end(), [](const Light& l) { return !l.from_environment; });
    if (punctual > 0)
        return fmt::format("the scene has {} punctual light(s); the path tracer samples only the environment", punctual);
    for (const Material& m : scene.materials)
        if (m.model == MaterialModel::Classic)
            return fmt::format("material '{}' is a classic Whitted material (it samples glTF materials only)", m.name);
    return {};
}

Film path_trace(const Renderer& renderer, const PathSettings& settings, int threads, PathStats* stats) {
    if (const std::string why = path_trace_refusal(renderer); !why.empty()) throw Error("path reference: " + why);
    const Scene& scene = renderer.view().scene();
    if (settings.spp < 1) throw Error(fmt::format("path reference: {} paths per pixel", settings.spp));
    const ImageSize size = renderer.image_size();
    const PixelWindow window = renderer.window();
    const CameraModel camera(scene.cameras[size_t(renderer.settings().camera)], size.width, size.height);
    Film film(size.width, size.height, window, AovSet{});
    const PathTracer tracer(renderer, settings);
    std::atomic<uint64_t> segments{0};
    const auto t0 = std::chrono::steady_clock::now();
    WorkerPool pool(threads);
    const int rows = window.height();
    pool.for_each(size_t(rows), [&](size_t row, int) {
        const int y = window.y0 + int(row);
        uint64_t local = 0;
        for (int x = window.x0; x < window.x1; ++x) {
            const uint64_t pixel = uint64_t(y) * uint64_t(size.width) + uint64_t(x);
            Color sum(0.f);
            for (int s = 0; s < settings.spp; ++s) {
                Rng rng{(pixel * 0x100000001b3ull + uint64_t(s)) ^ (settings.seed * 0xd1b54a32d192ed03ull)};
                rng.next();
                double px = x + 0.5, py = y + 0.5;
                if (settings.pixel_area) {
                    px = x + double(rng.uniform());
                    py = y + double(rng.uniform());
                }
                const Color c = tracer.radiance(camera.generate(px, py), rng, local);
                if (is_finite(c)) sum += c;
            }
            film.beauty[film.index(x, y)] = sum / float(settings.spp);
        }
        segments += local;
    });
    if (stats) {
        stats->paths = uint64_t(window.width()) * uint64_t(rows) * uint64_t(settings.spp);
        stats->segments = segments;
        stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    return film;
}

}  // namespace whitted::app
