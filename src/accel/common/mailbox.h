// Mailbox for structures that reference a primitive from several cells (grid, octree): a small
// direct-mapped cache, per ray, of the triangles already tested (Amanatides & Woo 1987 keep a ray
// id per primitive; that is not thread-safe for a const structure shared by all threads, so the
// mailbox lives on the ray's stack instead). A collision only costs a repeated test.
#pragma once

#include <cstdint>
#include <vector>

#include "accel/accelerator.h"
#include "accel/common/geometry.h"
#include "accel/common/primitives.h"

namespace whitted {

class Mailbox {
public:
    static constexpr uint32_t kSize = 64;   ///< entries; a power of two

    Mailbox() {
        for (uint32_t& e : m_prims) e = kInvalidId;
    }
    /// True when `prim` was tested before; otherwise records it and returns false.
    bool seen(uint32_t prim) {
        uint32_t& slot = m_prims[(prim * 2654435761u) >> 26];
        if (slot == prim) return true;
        slot = prim;
        return false;
    }

private:
    uint32_t m_prims[kSize];
};

/// Tests the primitives refs[begin, end) of the set `prims` (primitives.h) that the mailbox has
/// not seen yet against the query `q` (its tmax shrinks as hits are reported); true when the
/// query asks to stop (any-hit answered). The leaf loop shared by the grid's cells and the
/// octree's leaves.
template <typename P, typename Query>
inline bool test_mailboxed_refs(const std::vector<uint32_t>& refs, uint32_t begin, uint32_t end, const P& prims,
                                Mailbox& mailbox, const typename P::RayData& ray, float tnear, Query& q) {
    for (uint32_t r = begin; r < end; ++r) {
        const uint32_t prim = refs[r];
        if (mailbox.seen(prim)) continue;
        if (prims.intersect(ray, prim, prim, tnear, q)) return true;
    }
    return false;
}

}  // namespace whitted
