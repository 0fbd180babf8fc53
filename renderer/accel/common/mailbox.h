// Mailbox for structures that reference a triangle from several cells (grid, octree): a small
// direct-mapped cache, per ray, of the triangles already tested (Amanatides & Woo 1987 keep a ray
// id per primitive; that is not thread-safe for a const structure shared by all threads, so the
// mailbox lives on the ray's stack instead). A collision only costs a repeated test.
#pragma once

#include <cstdint>

#include "renderer/accel/accelerator.h"

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

}  // namespace whitted
