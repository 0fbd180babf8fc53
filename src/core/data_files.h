// Where whitted's own data files (the OCIO config, the bundled environment maps) live: beside the
// installed library or executable (<prefix>/share/whitted), or in the source tree it was built
// from (assets/). One lookup for the CLI, the C++ package and the Python module.
#pragma once

#include <string>
#include <vector>

namespace whitted {

/// The first existing file among the candidate places for `relative` (e.g. "ocio/config.ocio"):
/// $WHITTED_DATA_DIR/<relative>, <dir of the binary holding this code>/../share/whitted/<relative>,
/// the same beside the running executable, then the build and source trees' assets/<relative>.
/// Throws whitted::Error listing the places tried when none exists.
std::string data_file(const std::string& relative);

/// The candidate paths data_file() tries, in order (normalised; existing or not).
std::vector<std::string> data_file_candidates(const std::string& relative);

/// The folder of the binary (executable, libwhitted.so or the Python module) that holds
/// whitted's code, canonical; empty when it cannot be told. Also where the image module is
/// looked for (image_files.cpp).
std::string whitted_binary_dir();

}  // namespace whitted
