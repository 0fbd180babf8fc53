// Library messages (OpenImageIO, tinygltf) made into one line of a whitted::Error: control
// characters become spaces, trailing spaces go (private to importers/).
#pragma once

#include <string>

namespace whitted {

/// `s` with every control character replaced by a space and trailing spaces removed.
inline std::string one_line(std::string s) {
    for (char& c : s)
        if ((unsigned char)c < 0x20 || c == 0x7f) c = ' ';
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s;
}

}  // namespace whitted
