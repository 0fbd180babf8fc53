#include "accel/bvh/bvh_tree.h"

#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>
#include <tbb/blocked_range.h>

#include <algorithm>
#include <array>

#include "core/error.h"

namespace whitted {

namespace {

/// Levels below which SAH splits are allowed; deeper nodes split at the object median, which
/// halves the count and so bounds the depth by kSahMaxDepth + 32 < kBvhMaxDepth.
constexpr int kSahMaxDepth = 30;

template <typename T>
struct NodeBounds {
    Bounds3<T> box, centroids;
    void join(const NodeBounds& o) {
        box.extend(o.box);
        centroids.extend(o.centroids);
    }
};

template <typename T>
class Builder {
public:
    Builder(const std::vector<Bounds3<T>>& boxes, const BvhBuildConfig& config, std::vector<uint32_t>& ids)
        : m_boxes(boxes), m_config(config), m_ids(ids) {
        m_bins = std::clamp(config.bins, 2, 256);
        m_centroids.resize(boxes.size());
        for (size_t i = 0; i < boxes.size(); ++i) m_centroids[i] = boxes[i].center();
    }

    /// Builds into slots: a subtree over n primitives rooted at slot s uses slots [s, s + 2n - 1);
    /// its left child sits at s + 1 and its right child at s + 2 n_left. Slots depend only on the
    /// split decisions, so concurrent subtree builds never race and the result is deterministic.
    std::vector<BuildNode<T>> run() {
        const uint32_t n = uint32_t(m_ids.size());
        m_slots.assign(2 * size_t(n) - 1, BuildNode<T>{});
        build(0, 0, n, 0);
        return flatten();
    }

private:
    NodeBounds<T> bounds_of(uint32_t begin, uint32_t end) const {
        auto range_bounds = [&](uint32_t b, uint32_t e) {
            NodeBounds<T> nb;
            for (uint32_t i = b; i < e; ++i) {
                nb.box.extend(m_boxes[m_ids[i]]);
                nb.centroids.extend(m_centroids[m_ids[i]]);
            }
            return nb;
        };
        if (end - begin < m_config.parallel_threshold) return range_bounds(begin, end);
        // min/max reductions are exact: the parallel result equals the serial one.
        return tbb::parallel_reduce(
            tbb::blocked_range<uint32_t>(begin, end, 4096), NodeBounds<T>{},
            [&](const tbb::blocked_range<uint32_t>& r, NodeBounds<T> acc) {
                acc.join(range_bounds(r.begin(), r.end()));
                return acc;
            },
            [](NodeBounds<T> a, const NodeBounds<T>& b) {
                a.join(b);
                return a;
            });
    }

    struct Split {
        int axis = -1;
        int bin = 0;
        double cost = std::numeric_limits<double>::infinity();  ///< sum of area x blocks of both sides
    };

    /// Best binned split plane over the three axes (a separate frame so the bins do not stay on
    /// the stack during recursion).
    Split find_split(uint32_t begin, uint32_t end, const NodeBounds<T>& nb) const {
        Split best;
        const uint32_t count = end - begin;
        const Vec3<T> cext = nb.centroids.diagonal();
        for (int axis = 0; axis < 3; ++axis) {
            if (!(cext[axis] > T(0))) continue;
            const T scale = T(m_bins) / cext[axis];
            std::array<Bounds3<T>, 256> bin_box;
            std::array<uint32_t, 256> bin_count{};
            for (uint32_t i = begin; i < end; ++i) {
                const uint32_t id = m_ids[i];
                const int b = bin_of(m_centroids[id][axis], nb.centroids.lo[axis], scale);
                bin_box[size_t(b)].extend(m_boxes[id]);
                ++bin_count[size_t(b)];
            }
            // Sweep from the right, then from the left evaluating each plane between bins.
            std::array<double, 256> right_cost{};
            Bounds3<T> acc;
            uint32_t n_right = 0;
            for (int b = m_bins - 1; b > 0; --b) {
                acc.extend(bin_box[size_t(b)]);
                n_right += bin_count[size_t(b)];
                right_cost[size_t(b)] = double(half_area(acc)) * sah_blocks(n_right, m_config.leaf_block);
            }
            acc = Bounds3<T>{};
            uint32_t n_left = 0;
            for (int b = 0; b < m_bins - 1; ++b) {
                acc.extend(bin_box[size_t(b)]);
                n_left += bin_count[size_t(b)];
                if (n_left == 0 || n_left == count) continue;
                const double cost =
                    double(half_area(acc)) * sah_blocks(n_left, m_config.leaf_block) + right_cost[size_t(b) + 1];
                if (cost < best.cost) best = {axis, b + 1, cost};
            }
        }
        return best;
    }

    void make_leaf(uint32_t slot, uint32_t begin, uint32_t end, const Bounds3<T>& box) {
        BuildNode<T>& node = m_slots[slot];
        node.box = box;
        node.index = begin;
        node.count = end - begin;
        node.begin = begin;
        node.end = end;
    }

    void build(uint32_t slot, uint32_t begin, uint32_t end, int depth) {
        const NodeBounds<T> nb = bounds_of(begin, end);
        const uint32_t count = end - begin;
        if (count <= 1) return make_leaf(slot, begin, end, nb.box);

        // Binned SAH over the centroid bounds (Wald 2007).
        const Vec3<T> cext = nb.centroids.diagonal();
        const Split split = depth < kSahMaxDepth ? find_split(begin, end, nb) : Split{};
        const int best_axis = split.axis, best_bin = split.bin;
        const double best_cost = split.cost;

        uint32_t mid = 0;
        const double area = std::max(double(half_area(nb.box)), std::numeric_limits<double>::min());
        const double leaf_cost = double(m_config.intersection_cost) * sah_blocks(count, m_config.leaf_block);
        if (best_axis >= 0) {
            const double split_cost = m_config.traversal_cost + m_config.intersection_cost * best_cost / area;
            if (split_cost >= leaf_cost && count <= uint32_t(std::max(1, m_config.max_leaf_size)))
                return make_leaf(slot, begin, end, nb.box);
            const T lo = nb.centroids.lo[best_axis];
            const T scale = T(m_bins) / cext[best_axis];
            auto* first = m_ids.data() + begin;
            auto* split_at = std::partition(first, m_ids.data() + end, [&](uint32_t id) {
                return bin_of(m_centroids[id][best_axis], lo, scale) < best_bin;
            });
            mid = uint32_t(split_at - m_ids.data());
        } else {
            // No usable plane (all centroids equal, or too deep): leaf if small, else median.
            if (count <= uint32_t(std::max(1, m_config.max_leaf_size)) && depth < kSahMaxDepth)
                return make_leaf(slot, begin, end, nb.box);
            if (count <= 1) return make_leaf(slot, begin, end, nb.box);
            const int axis = cext.x >= cext.y && cext.x >= cext.z ? 0 : (cext.y >= cext.z ? 1 : 2);
            mid = begin + count / 2;
            std::nth_element(m_ids.data() + begin, m_ids.data() + mid, m_ids.data() + end, [&](uint32_t a, uint32_t b) {
                const T ca = m_centroids[a][axis], cb = m_centroids[b][axis];
                return ca != cb ? ca < cb : a < b;
            });
        }
        RT_DCHECK(mid > begin && mid < end);

        BuildNode<T>& node = m_slots[slot];
        node.box = nb.box;
        node.count = 0;
        node.begin = begin;
        node.end = end;
        const uint32_t left = slot + 1, right = slot + 2 * (mid - begin);
        node.index = left;  // slot numbers; flatten() renumbers
        if (count >= m_config.parallel_threshold) {
            tbb::parallel_invoke([&] { build(left, begin, mid, depth + 1); },
                                 [&] { build(right, mid, end, depth + 1); });
        } else {
            build(left, begin, mid, depth + 1);
            build(right, mid, end, depth + 1);
        }
    }

    int bin_of(T c, T lo, T scale) const { return std::clamp(int((c - lo) * scale), 0, m_bins - 1); }

    /// Renumbers the slot tree depth-first with sibling pairs adjacent.
    std::vector<BuildNode<T>> flatten() const {
        std::vector<BuildNode<T>> out;
        out.reserve(m_slots.size());
        out.push_back(m_slots[0]);
        // (slot of the source node, index of its copy in `out`)
        std::vector<std::pair<uint32_t, uint32_t>> stack{{0u, 0u}};
        while (!stack.empty()) {
            auto [slot, at] = stack.back();
            stack.pop_back();
            const BuildNode<T>& src = m_slots[slot];
            if (src.count != 0) continue;
            const uint32_t left = slot + 1, right = slot + 2 * (m_slots[left].end - m_slots[left].begin);
            const uint32_t first = uint32_t(out.size());
            out.push_back(m_slots[left]);
            out.push_back(m_slots[right]);
            out[at].index = first;
            stack.push_back({right, first + 1});
            stack.push_back({left, first});
        }
        return out;
    }

    const std::vector<Bounds3<T>>& m_boxes;
    const BvhBuildConfig& m_config;
    std::vector<uint32_t>& m_ids;
    std::vector<Vec3<T>> m_centroids;
    std::vector<BuildNode<T>> m_slots;
    int m_bins = 16;
};

}  // namespace

template <typename T>
std::vector<BuildNode<T>> build_bvh(const std::vector<Bounds3<T>>& boxes, const BvhBuildConfig& config,
                                    std::vector<uint32_t>& ids) {
    ids.resize(boxes.size());
    for (size_t i = 0; i < ids.size(); ++i) ids[i] = uint32_t(i);
    if (boxes.empty()) return {};
    RT_CHECK(boxes.size() < (size_t(1) << 31));
    return Builder<T>(boxes, config, ids).run();
}

template <typename T>
double sah_cost(const std::vector<BuildNode<T>>& nodes, const BvhBuildConfig& config) {
    if (nodes.empty()) return 0.0;
    const double root = std::max(double(half_area(nodes[0].box)), std::numeric_limits<double>::min());
    double cost = 0.0;
    for (const BuildNode<T>& n : nodes) {
        const double ratio = double(half_area(n.box)) / root;
        cost += ratio * (n.count == 0 ? double(config.traversal_cost)
                                      : double(config.intersection_cost) * sah_blocks(n.count, config.leaf_block));
    }
    return cost;
}

template std::vector<BuildNode<float>> build_bvh(const std::vector<Bounds3<float>>&, const BvhBuildConfig&,
                                                 std::vector<uint32_t>&);
template std::vector<BuildNode<double>> build_bvh(const std::vector<Bounds3<double>>&, const BvhBuildConfig&,
                                                  std::vector<uint32_t>&);
template double sah_cost(const std::vector<BuildNode<float>>&, const BvhBuildConfig&);
template double sah_cost(const std::vector<BuildNode<double>>&, const BvhBuildConfig&);

}  // namespace whitted
