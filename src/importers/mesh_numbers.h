// Numbers of an imported mesh the renderer cannot use as given (private to importers/): denormal
// values are flushed to 0 and degenerate triangles counted, each kind reported by one warning
// with a count (docs/numerical-stability.md, "Bad numbers in input"). NaN and infinite values
// are rejected earlier, by the importers' own validation, with a located error.
#pragma once

#include <cstddef>
#include <string>

#include "importers/warning_log.h"
#include "scene/scene.h"

namespace whitted {

struct MeshNumberReport {
    size_t denormals = 0;        ///< position / normal / UV / color components flushed to 0
    size_t zero_area = 0;        ///< triangles whose float cross product is 0 (never hit)
};

/// Flushes denormal components (|x| < FLT_MIN; the render threads run with denormals-are-zero, so
/// backends would disagree on them otherwise) of every attribute to 0 and counts zero-area
/// triangles. Returns what it found; the mesh is changed in place.
MeshNumberReport sanitize_mesh_numbers(Mesh& mesh);

/// Adds one warning per kind found ("<where>: 3 zero-area triangle(s): never hit").
void report_mesh_numbers(const MeshNumberReport& report, const std::string& where, WarningLog& log);

}  // namespace whitted
