// Denormal flushing and degenerate-triangle counts for imported meshes (mesh_numbers.h).

#include "importers/mesh_numbers.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace whitted {

namespace {

/// Flushes a denormal float to (signed) zero; counts it.
void flush(float& v, size_t& count) {
    if (v != 0.f && std::fabs(v) < std::numeric_limits<float>::min()) {
        v = std::copysign(0.f, v);
        ++count;
    }
}

}  // namespace

MeshNumberReport sanitize_mesh_numbers(Mesh& mesh) {
    MeshNumberReport r;
    for (Vec3f& p : mesh.positions)
        for (int k = 0; k < 3; ++k) flush(p[k], r.denormals);
    for (Vec3f& n : mesh.normals)
        for (int k = 0; k < 3; ++k) flush(n[k], r.denormals);
    for (std::vector<Vec2f>* uvs : {&mesh.uv0, &mesh.uv1})
        for (Vec2f& uv : *uvs) flush(uv.x, r.denormals), flush(uv.y, r.denormals);
    for (Vec4f& c : mesh.colors) flush(c.x, r.denormals), flush(c.y, r.denormals), flush(c.z, r.denormals), flush(c.w, r.denormals);
    // Zero area in float: the watertight test's determinant is 0 for every ray, so nothing hits
    // the triangle; it stays in the index list so primitive ids keep their meaning.
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const Vec3f& a = mesh.positions[mesh.indices[t]];
        const Vec3f& b = mesh.positions[mesh.indices[t + 1]];
        const Vec3f& c = mesh.positions[mesh.indices[t + 2]];
        if (cross(b - a, c - a) == Vec3f(0.f)) ++r.zero_area;
    }
    return r;
}

void report_mesh_numbers(const MeshNumberReport& r, const std::string& where, WarningLog& log) {
    if (r.denormals > 0)
        log.add("denormals", fmt::format("{}: {} denormal value(s) (|x| < 1.18e-38) flushed to 0", where, r.denormals));
    if (r.zero_area > 0)
        log.add("zero-area", fmt::format("{}: {} zero-area triangle(s): kept, never hit", where, r.zero_area));
}

}  // namespace whitted
