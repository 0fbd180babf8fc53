// The path-traced reference of `whitted bench env` (path_reference.h).
#include "benchmarks/path_reference.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"
#include "core/parallel.h"
#include "integrator/camera.h"
#include "integrator/shading_frame.h"
#include "shading/environment_map.h"
#include "shading/material_mapping.h"
#include "shading/optics.h"

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

/// An orthonormal basis about unit n (Duff et al. 2017).
struct Basis {
    Vec3f t, b, n;
    explicit Basis(const Vec3f& nn) : n(nn) {
        const float sign = std::copysign(1.f, n.z);
        const float a = -1.f / (sign + n.z);
        const float bb = n.x * n.y * a;
        t = Vec3f(1.f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
        b = Vec3f(bb, sign + n.y * n.y * a, -n.y);
    }
    Vec3f world(float x, float y, float z) const { return t * x + b * y + n * z; }
};

float luminance(const Color& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

/// Smith's height-correlated visibility V = G / (4 N.L N.V) for GGX (glTF Appendix B).
float smith_visibility(float nl, float nv, float a2) {
    const float gv = nl * std::sqrt(nv * nv * (1.f - a2) + a2);
    const float gl = nv * std::sqrt(nl * nl * (1.f - a2) + a2);
    const float s = gv + gl;
    return s > 0.f ? 0.5f / s : 0.f;
}

/// The material at one hit, as the path needs it.
struct Bsdf {
    Color base;           ///< base colour (linear RGB)
    float metallic = 0.f, roughness = 1.f, transmission = 0.f;
    Color f0_dielectric;  ///< KHR_materials_ior / specular
    float ior = 1.5f;
    bool volume = false;

    /// F at V.H of the specular lobe: the metal's and the dielectric's, mixed by metallic.
    Color fresnel(float vh) const {
        return schlick(base, vh) * metallic + schlick(f0_dielectric, vh) * (1.f - metallic);
    }
};

class PathTracer {
public:
    PathTracer(const Renderer& r, const PathSettings& s)
        : m_view(r.view()), m_accel(r.accelerator()), m_offset(r.accelerator().ray_offset()),
          m_env(*r.view().environment()), m_settings(s) {}

    /// Radiance along one camera ray.
    Color radiance(Ray ray, Rng& rng, uint64_t& segments) const {
        Color L(0.f), beta(1.f);
        RayKind kind = RayKind::Camera;
        for (int bounce = 0; bounce < m_settings.max_bounces; ++bounce) {
            ++segments;
            const Hit hit = m_accel.intersect(ray, kind);
            if (!hit.valid()) return L + beta * m_env.radiance(ray.dir);
            const SurfacePoint sp = m_view.surface(ray, hit);
            const ShadingFrame f = shading_frame(sp, ray.dir);
            const Material& mat = m_view.scene().materials[sp.material];
            const PbrSample in = m_view.material_inputs(mat, sp);
            if (mat.unlit) return L + beta * Color(in.base_color.x, in.base_color.y, in.base_color.z);
            L += beta * in.emissive;
            // BLEND coverage: the path passes the surface with probability 1 - alpha.
            if (mat.alpha_mode == AlphaMode::Blend && rng.uniform() >= in.base_color.w) {
                ray = spawn_ray(m_offset, sp, -f.Ng, ray.dir);
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

            Color weight(0.f);
            Vec3f dir;
            bool through = false;
            if (!sample(b, f, rng, weight, dir, through)) return L;
            beta *= weight;
            if (!is_finite(beta) || is_black(beta)) return L;
            ray = spawn_ray(m_offset, sp, through ? -f.Ng : f.Ng, dir);
            kind = through ? RayKind::Refraction : RayKind::Reflection;
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
    /// Picks one lobe (specular, diffuse, transmission) with a probability in proportion to its
    /// rough weight at this view and samples a direction from it. `weight` = f cos / (pdf p_lobe).
    /// False: the path ends (no lobe, or a direction under the geometric surface).
    bool sample(const Bsdf& b, const ShadingFrame& f, Rng& rng, Color& weight, Vec3f& dir, bool& through) const {
        const Vec3f& N = f.N;
        const Vec3f& V = f.V;
        const float nv = std::max(dot(N, V), 1e-6f);
        const float dielectric = 1.f - b.metallic;
        const float fd = max_component(schlick(b.f0_dielectric, nv));
        const float w_spec = b.metallic * max_component(schlick(b.base, nv)) + dielectric * fd;
        const float w_diff = dielectric * (1.f - b.transmission) * (1.f - fd) * luminance(b.base);
        const float w_trans = dielectric * b.transmission * (1.f - fd) * luminance(b.base);
        const float total = w_spec + w_diff + w_trans;
        if (!(total > 0.f)) return false;
        const float u = rng.uniform() * total;
        const float u1 = rng.uniform(), u2 = rng.uniform();
        const Basis basis(N);
        through = false;
        if (u < w_spec) {
            const float p = w_spec / total;
            if (b.roughness < kDeltaRoughness) {
                dir = reflect(V, N);
                weight = b.fresnel(nv) / p;
            } else {
                // GGX half vector by D(h) N.H: the weight is F V 4 N.L V.H / N.H (D cancels).
                const float a = b.roughness * b.roughness, a2 = a * a;
                const float phi = 2.f * kPi * u1;
                const float cos_h = std::sqrt((1.f - u2) / (1.f + (a2 - 1.f) * u2));
                const float sin_h = std::sqrt(std::max(0.f, 1.f - cos_h * cos_h));
                const Vec3f h = basis.world(sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h);
                const float vh = dot(V, h);
                if (vh <= 0.f) return false;
                dir = reflect(V, h);
                const float nl = dot(N, dir);
                if (nl <= 0.f) return false;
                weight = b.fresnel(vh) * (smith_visibility(nl, nv, a2) * 4.f * nl * vh / cos_h / p);
            }
        } else if (u < w_spec + w_diff) {
            const float p = w_diff / total;
            // Cosine-weighted: the weight is the albedo times what the dielectric's Fresnel at V.H
            // leaves to the diffuse layer.
            const float r = std::sqrt(u1), phi = 2.f * kPi * u2;
            dir = basis.world(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.f, 1.f - u1)));
            const Vec3f h = normalize(dir + V);
            const Color keep = Color(1.f) - schlick(b.f0_dielectric, std::max(dot(V, h), 0.f));
            weight = b.base * keep * (dielectric * (1.f - b.transmission) / p);
        } else {
            const float p = w_trans / total;
            const Color keep = Color(1.f) - schlick(b.f0_dielectric, nv);
            weight = b.base * keep * (dielectric * b.transmission / p);
            through = true;
            dir = -V;
            if (b.volume) {
                // Snell at the smooth interface; total internal reflection sends it back.
                const float eta = f.front ? 1.f / b.ior : b.ior;
                if (const auto t = refract(-V, N, eta)) {
                    dir = *t;
                } else {
                    dir = reflect(V, N);
                    through = false;
                }
            }
        }
        // Reflected directions under the geometric surface (a shading normal's artefact) end the path.
        if (!through && dot(dir, f.Ng) <= 0.f) return false;
        if (through && dot(dir, f.Ng) >= 0.f) return false;
        return true;
    }

    const SceneView& m_view;
    const Accelerator& m_accel;
    RayOffsetPolicy m_offset;
    const EnvironmentMap& m_env;
    PathSettings m_settings;
};

}  // namespace

size_t punctual_lights(const Scene& scene) {
    return size_t(std::count_if(scene.lights.begin(), scene.lights.end(), [](const Light& l) { return !l.from_environment; }));
}

Film path_trace(const Renderer& renderer, const PathSettings& settings, int threads, PathStats* stats) {
    const Scene& scene = renderer.view().scene();
    if (!renderer.view().environment())
        throw Error("path reference: the scene has no environment (it is meant for environment-lit scenes)");
    if (const size_t n = punctual_lights(scene))
        throw Error(fmt::format("path reference: the scene has {} punctual light(s); the path tracer samples only "
                                "the environment",
                                n));
    for (const Material& m : scene.materials)
        if (m.model == MaterialModel::Classic)
            throw Error(fmt::format("path reference: material '{}' is a classic Whitted material (it samples glTF "
                                    "materials only)",
                                    m.name));
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
