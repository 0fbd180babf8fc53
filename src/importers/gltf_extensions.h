// How whitted handles each glTF extension (private to importers/; docs/gltf-support.md is the
// user-facing copy of this table).
#pragma once

#include <string>

#include "scene/scene.h"

namespace whitted::gltf {

struct ExtensionPolicy {
    ExtensionSupport support = ExtensionSupport::Ignored;
    bool refuse_if_required = true;  ///< an Ignored extension the file requires is an error
    std::string note;                ///< what whitted does with it (shown by `whitted info`)
    bool known = false;              ///< listed in the table (false = unknown extension)
};

/// The policy for an extension name; unknown names are Ignored (and refused when required).
ExtensionPolicy extension_policy(const std::string& name);

}  // namespace whitted::gltf
