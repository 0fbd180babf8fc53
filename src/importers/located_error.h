// Building whitted::Error locations (private to importers/).
#pragma once

#include <string>

#include "core/error.h"

namespace whitted {

/// FileLoc for a file and an optional JSON pointer (no line/column: glTF is located by pointer).
inline FileLoc file_loc(const std::string& file, const std::string& pointer = {}) {
    FileLoc loc;
    loc.file = file;
    loc.pointer = pointer;
    return loc;
}

}  // namespace whitted
