#include "accel/factory/create_accelerator.h"

#include <cstdlib>
#include <sstream>
#include <vector>

#include "accel/bvh/bvh_accel.h"
#include "accel/common/planes.h"
#include "accel/embree/embree_accel.h"
#include "accel/grid/grid_accel.h"
#include "accel/octree/octree_accel.h"
#include "core/error.h"
#include "scene/scene.h"

namespace whitted {

namespace {

/// "name:key=value,key=value" split into the name and its options, with strict value parsers
/// that name the spec and the key in their error.
class AccelSpec {
public:
    explicit AccelSpec(const std::string& spec) : m_spec(spec) {
        const size_t colon = spec.find(':');
        m_name = spec.substr(0, colon);
        if (colon == std::string::npos) return;
        std::stringstream in(spec.substr(colon + 1));
        std::string item;
        while (std::getline(in, item, ',')) {
            const size_t eq = item.find('=');
            if (item.empty() || eq == std::string::npos || eq == 0)
                throw Error(fmt::format("accelerator '{}': option '{}' is not key=value", spec, item));
            m_options.push_back({item.substr(0, eq), item.substr(eq + 1), false});
        }
    }
    const std::string& name() const { return m_name; }

    /// The value of `key`, or nullptr when not given.
    const std::string* find(const std::string& key) {
        for (Option& o : m_options)
            if (o.key == key) {
                o.used = true;
                return &o.value;
            }
        return nullptr;
    }
    template <typename T>
    void number(const std::string& key, T& out, double lo, double hi) {
        const std::string* v = find(key);
        if (!v) return;
        char* end = nullptr;
        const double d = std::strtod(v->c_str(), &end);
        if (v->empty() || *end != '\0' || !(d >= lo && d <= hi))
            throw Error(fmt::format("accelerator '{}': {}={} is not a number in [{}, {}]", m_spec, key, *v, lo, hi));
        out = T(d);
    }
    void precision(Precision& out) {
        const std::string* v = find("precision");
        if (!v) return;
        if (*v == "float") out = Precision::Float;
        else if (*v == "double") out = Precision::Double;
        else throw Error(fmt::format("accelerator '{}': precision must be float or double", m_spec));
    }
    void build(BvhBuildConfig& b) {
        number("bins", b.bins, 2, 256);
        number("leaf", b.max_leaf_size, 1, 256);
        number("traversal_cost", b.traversal_cost, 0, 1e6);
        number("intersection_cost", b.intersection_cost, 1e-6, 1e6);
        number("block", b.leaf_block, 1, 64);
    }
    /// Throws for options no backend setting consumed.
    void check_all_used(const char* valid) const {
        for (const Option& o : m_options)
            if (!o.used)
                throw Error(fmt::format("accelerator '{}': unknown option '{}' (valid for {}: {})", m_spec, o.key, m_name,
                                        valid));
    }

private:
    struct Option {
        std::string key, value;
        bool used;
    };
    std::string m_spec, m_name;
    std::vector<Option> m_options;
};

}  // namespace

const std::vector<std::string>& accelerator_names() {
    static const std::vector<std::string> names{"embree", "bvh", "grid", "octree", "kdop", "brute"};
    return names;
}

namespace {

/// The backend alone, without the scene's infinite planes.
std::unique_ptr<Accelerator> create_backend(const std::string& name, const Scene& scene, const SurfaceFilter& filter,
                                            const AccelConfig& config) {
    AccelSpec spec(name);
    if (spec.name() == "embree") {
        EmbreeConfig c{config.robust, config.threads};
        auto width = [&](const char* key, int& value) {
            if (const std::string* p = spec.find(key)) {
                if (*p == "1" || *p == "4" || *p == "8" || *p == "16") value = std::stoi(*p);
                else throw Error(fmt::format("accelerator '{}': {} must be 1, 4, 8 or 16", name, key));
            }
        };
        width("packet", c.packet_width);
        width("shadow_packet", c.shadow_packet_width);
        if (const std::string* k = spec.find("compact")) {
            if (*k == "0" || *k == "1") c.compact = *k == "1";
            else throw Error(fmt::format("accelerator '{}': compact must be 0 or 1", name));
        }
        if (const std::string* f = spec.find("flatten")) {
            if (*f == "0" || *f == "1") c.flatten = *f == "1";
            else throw Error(fmt::format("accelerator '{}': flatten must be 0 or 1", name));
        }
        spec.check_all_used("packet, shadow_packet, compact, flatten");
        return create_embree_accelerator(scene, filter, c);
    }
    if (spec.name() == "bvh") {
        BvhConfig c;
        spec.precision(c.precision);
        if (const std::string* bv = spec.find("bv")) {
            if (*bv == "aabb") c.volume = BoundingVolume::Aabb;
            else if (*bv == "sphere") c.volume = BoundingVolume::Sphere;
            else throw Error(fmt::format("accelerator '{}': bv must be aabb or sphere", name));
        }
        if (const std::string* w = spec.find("width")) {
            if (*w == "2" || *w == "4" || *w == "8") c.width = std::stoi(*w);
            else throw Error(fmt::format("accelerator '{}': width must be 2, 4 or 8", name));
            if (c.width != 2 && (c.precision == Precision::Double || c.volume == BoundingVolume::Sphere))
                throw Error(fmt::format("accelerator '{}': width {} needs precision=float and bv=aabb (the double "
                                        "and sphere BVHs are binary)", name, c.width));
        } else if (c.precision == Precision::Double || c.volume == BoundingVolume::Sphere) {
            c.width = 2;
        }
        // Wide trees test leaf triangles four at a time: the SAH counts them in blocks of four.
        if (c.width != 2) c.build = wide_bvh_build_defaults();
        spec.build(c.build);
        if (const std::string* isa = spec.find("isa")) {
            if (*isa == "auto") c.allow_avx2 = true;
            else if (*isa == "sse2") c.allow_avx2 = false;
            else throw Error(fmt::format("accelerator '{}': isa must be auto or sse2", name));
        }
        if (const std::string* f = spec.find("flatten")) {
            if (*f == "0" || *f == "1") c.flatten = *f == "1";
            else throw Error(fmt::format("accelerator '{}': flatten must be 0 or 1", name));
        }
        spec.check_all_used("precision, bv, width, isa, flatten, bins, leaf, traversal_cost, intersection_cost, block");
        return create_bvh_accelerator(scene, filter, c);
    }
    if (spec.name() == "kdop") {
        KdopConfig c;
        spec.build(c.build);
        spec.check_all_used("bins, leaf, traversal_cost, intersection_cost, block");
        return create_kdop_accelerator(scene, filter, c);
    }
    if (spec.name() == "brute") {
        BruteForceConfig c;
        spec.precision(c.precision);
        spec.check_all_used("precision");
        return create_brute_force_accelerator(scene, filter, c);
    }
    if (spec.name() == "grid") {
        GridConfig c;
        spec.number("lambda", c.lambda, 0.01, 1000);
        spec.number("max_res", c.max_resolution, 1, 4096);
        spec.check_all_used("lambda, max_res");
        return create_grid_accelerator(scene, filter, c);
    }
    if (spec.name() == "octree") {
        OctreeConfig c;
        spec.number("leaf", c.max_leaf_size, 1, 1e6);
        spec.number("depth", c.max_depth, 0, 20);
        spec.check_all_used("leaf, depth");
        return create_octree_accelerator(scene, filter, c);
    }
    throw Error(fmt::format("unknown accelerator '{}' (available: embree, bvh, grid, octree, kdop, brute)", spec.name()));
}

}  // namespace

std::unique_ptr<Accelerator> create_accelerator(const std::string& name, const Scene& scene,
                                                const SurfaceFilter& filter, const AccelConfig& config) {
    std::unique_ptr<Accelerator> accel = create_backend(name, scene, filter, config);
    // Infinite planes stay out of every structure and are tested beside it (planes.h).
    if (!scene.planes.empty()) accel = std::make_unique<PlaneDecorator>(std::move(accel), scene, filter);
    return accel;
}

void set_accelerator_memory_limit(size_t bytes) { set_embree_memory_limit(bytes); }

}  // namespace whitted
