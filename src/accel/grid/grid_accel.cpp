#include "accel/grid/grid_accel.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "accel/common/mailbox.h"
#include "accel/bvh/two_level.h"

namespace whitted {

namespace {

/// A uniform grid over a primitive set P (one mesh's triangles, or the scene's spheres): cell c
/// holds m_refs[m_start[c], m_start[c + 1]) (primitive indices, ascending), cells ordered x
/// fastest. A primitive is entered into the cells its overlap test accepts (for spheres: the
/// cells the surface passes through).
template <typename P>
class PrimGrid {
public:
    PrimGrid(P prims, const GridConfig& config) : m_prims(std::move(prims)) {
        for (uint32_t i = 0; i < m_prims.size(); ++i) m_bounds.extend(m_prims.bounds(i));
        choose_resolution(config);
        bin_prims();
    }

    template <class Query>
    bool traverse(const Vec3f& org, const Vec3f& dir, float tnear, Query& q) const {
        // Clip the ray to the grid box.
        const Vec3f lo(m_lo[0], m_lo[1], m_lo[2]), hi(m_hi[0], m_hi[1], m_hi[2]);
        const SlabRay<float> slab(org, dir, abs_extent(lo, hi));
        const float t_enter = slab_entry(slab, lo, hi, tnear, q.tmax);
        if (t_enter == kInfinity) return false;
        float t_exit = q.tmax * kRayTmaxScale<float> + slab.t_slack;
        for (int a = 0; a < 3; ++a) {
            const float t_far = ((slab.neg[a] ? m_lo[a] : m_hi[a]) - org[a]) * slab.inv_dir[a] * kSlabExitScale<float>;
            t_exit = t_far < t_exit ? t_far : t_exit;
        }

        // DDA set-up: the entry cell, the t of the next boundary and the t step per axis.
        const Vec3f entry = org + dir * t_enter;
        int cell[3], step[3], out[3];
        float next[3], delta[3];
        for (int a = 0; a < 3; ++a) {
            cell[a] = std::clamp(int((entry[a] - m_lo[a]) * m_inv_cell[a]), 0, m_res[a] - 1);
            if (dir[a] > 0.f) {
                step[a] = 1;
                out[a] = m_res[a];
                next[a] = (m_lo[a] + float(cell[a] + 1) * m_cell[a] - org[a]) / dir[a];
                delta[a] = m_cell[a] / dir[a];
            } else if (dir[a] < 0.f) {
                step[a] = -1;
                out[a] = -1;
                next[a] = (m_lo[a] + float(cell[a]) * m_cell[a] - org[a]) / dir[a];
                delta[a] = -m_cell[a] / dir[a];
            } else {  // +0 or -0: never crosses a boundary of this axis
                step[a] = 0;
                out[a] = -2;
                next[a] = kInfinity;
                delta[a] = kInfinity;
            }
        }

        const typename P::RayData pr = P::ray_data(org, dir);
        Mailbox mailbox;
        for (int guard = m_res[0] + m_res[1] + m_res[2] + 3; guard > 0; --guard) {
            // Test the primitives of this cell not tested before. A hit beyond the cell stays the
            // pending closest hit (its t is the query's tmax) and is accepted once the walk
            // reaches the cell that contains it.
            const size_t c = (size_t(cell[2]) * size_t(m_res[1]) + size_t(cell[1])) * size_t(m_res[0]) + size_t(cell[0]);
            if (test_mailboxed_refs(m_refs, m_start[c], m_start[c + 1], m_prims, mailbox, pr, tnear, q)) return true;
            // Step to the neighbour across the nearest boundary (Amanatides & Woo 1987).
            const int a = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
            const float cell_exit = next[a];
            if (q.tmax <= cell_exit || cell_exit > t_exit || step[a] == 0) return false;
            cell[a] += step[a];
            if (cell[a] == out[a]) return false;
            next[a] += delta[a];
        }
        return false;
    }

    Bounds3f bounds() const { return m_bounds; }
    BlasStats stats() const {
        return {m_start.size() * 4 + m_refs.size() * 4 + m_prims.bytes(), m_start.size() - 1, m_refs.size(), 0.0};
    }

private:
    void choose_resolution(const GridConfig& config) {
        const Vec3f ext = m_bounds.diagonal();
        const float max_ext = max_component(ext);
        // Flat axes get one cell; the volume uses a tiny thickness for them.
        const float thin = std::max(max_ext * 1e-3f, 1e-30f);
        const double volume = double(std::max(ext.x, thin)) * std::max(ext.y, thin) * std::max(ext.z, thin);
        double k = std::cbrt(double(config.lambda) * double(m_prims.size()) / volume);
        for (;;) {
            size_t cells = 1;
            for (int a = 0; a < 3; ++a) {
                m_res[a] = ext[a] <= thin ? 1 : int(std::clamp(std::round(double(ext[a]) * k), 1.0, double(config.max_resolution)));
                cells *= size_t(m_res[a]);
            }
            if (cells <= config.max_cells) break;
            k *= 0.9;
        }
        // Pad the box slightly so that vertices on its faces land inside a cell. The pad also scales
        // with the coordinates' magnitude: a flat or point-sized box far from the origin must still
        // get cells of non-zero float size (1e-30 alone vanishes next to a coordinate of 1).
        for (int a = 0; a < 3; ++a) {
            const float mag = std::max(std::fabs(m_bounds.lo[a]), std::fabs(m_bounds.hi[a]));
            const float pad = std::max(ext[a], max_ext) * 1e-5f + mag * 1e-6f + 1e-30f;
            m_lo[a] = m_bounds.lo[a] - pad;
            m_hi[a] = m_bounds.hi[a] + pad;
            m_cell[a] = (m_hi[a] - m_lo[a]) / float(m_res[a]);
            m_inv_cell[a] = 1.f / m_cell[a];
        }
    }

    /// Cells primitive i overlaps (its overlap test inside its bounding range of cells).
    template <class F>
    void for_each_cell(uint32_t i, F&& f) const {
        const Bounds3f b = m_prims.bounds(i);
        int c0[3], c1[3];
        for (int a = 0; a < 3; ++a) {
            c0[a] = std::clamp(int((b.lo[a] - m_lo[a]) * m_inv_cell[a]) - 1, 0, m_res[a] - 1);
            c1[a] = std::clamp(int((b.hi[a] - m_lo[a]) * m_inv_cell[a]) + 1, 0, m_res[a] - 1);
        }
        for (int z = c0[2]; z <= c1[2]; ++z)
            for (int y = c0[1]; y <= c1[1]; ++y)
                for (int x = c0[0]; x <= c1[0]; ++x) {
                    const Vec3f lo{m_lo[0] + float(x) * m_cell[0], m_lo[1] + float(y) * m_cell[1], m_lo[2] + float(z) * m_cell[2]};
                    const Vec3f hi = lo + Vec3f(m_cell[0], m_cell[1], m_cell[2]);
                    if (m_prims.overlaps_box(i, lo, hi))
                        f((size_t(z) * size_t(m_res[1]) + size_t(y)) * size_t(m_res[0]) + size_t(x));
                }
    }

    /// Counting sort of (cell, primitive) pairs: counts in parallel per primitive, then fills in
    /// primitive order, so each cell lists its primitives ascending whatever the thread count.
    void bin_prims() {
        const size_t cells = size_t(m_res[0]) * size_t(m_res[1]) * size_t(m_res[2]);
        const size_t n = m_prims.size();
        std::vector<uint32_t> per_prim(n + 1, 0);
        tbb::parallel_for(size_t(0), n, [&](size_t i) {
            uint32_t c = 0;
            for_each_cell(uint32_t(i), [&](size_t) { ++c; });
            per_prim[i + 1] = c;
        });
        for (size_t i = 0; i < n; ++i) per_prim[i + 1] += per_prim[i];
        std::vector<uint32_t> pair_cell(per_prim[n]);
        tbb::parallel_for(size_t(0), n, [&](size_t i) {
            uint32_t k = per_prim[i];
            for_each_cell(uint32_t(i), [&](size_t c) { pair_cell[k++] = uint32_t(c); });
        });
        m_start.assign(cells + 1, 0);
        for (uint32_t c : pair_cell) ++m_start[c + 1];
        for (size_t c = 0; c < cells; ++c) m_start[c + 1] += m_start[c];
        m_refs.resize(pair_cell.size());
        std::vector<uint32_t> fill(m_start.begin(), m_start.end() - 1);
        for (size_t i = 0; i < n; ++i)
            for (uint32_t k = per_prim[i]; k < per_prim[i + 1]; ++k) m_refs[fill[pair_cell[k]]++] = uint32_t(i);
    }

    P m_prims;
    Bounds3f m_bounds;
    int m_res[3] = {1, 1, 1};
    float m_lo[3] = {}, m_hi[3] = {}, m_cell[3] = {}, m_inv_cell[3] = {};
    std::vector<uint32_t> m_start, m_refs;
};

}  // namespace

std::unique_ptr<Accelerator> create_grid_accelerator(const Scene& scene, const SurfaceFilter& filter,
                                                     const GridConfig& config) {
    using Blas = PrimGrid<TrianglePrims<float>>;
    using SphereBlas = PrimGrid<AnalyticPrims<float>>;
    // The mesh builder outlives this call (update() builds a deformed mesh again): config by value.
    return std::make_unique<TwoLevelAccelerator<float, Blas, SphereBlas>>(
        "grid", scene, filter, [config](const Mesh& m) { return Blas(TrianglePrims<float>(m), config); },
        [&](AnalyticPrims<float>&& s) { return SphereBlas(std::move(s), config); }, true);
}

}  // namespace whitted
