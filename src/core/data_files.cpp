#include "core/data_files.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/error.h"

namespace whitted {

namespace {

namespace fs = std::filesystem;

/// The folder of the binary (shared library or executable) that holds this function.
fs::path this_binary_dir() {
    Dl_info info{};
    if (dladdr(reinterpret_cast<const void*>(&this_binary_dir), &info) && info.dli_fname) {
        std::error_code ec;
        const fs::path p = fs::canonical(info.dli_fname, ec);
        if (!ec) return p.parent_path();
    }
    return {};
}

/// The folder of the running executable.
fs::path executable_dir() {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    return ec ? fs::path{} : exe.parent_path();
}

}  // namespace

std::string whitted_binary_dir() { return this_binary_dir().string(); }

std::vector<std::string> data_file_candidates(const std::string& relative) {
    std::vector<fs::path> c;
    if (const char* dir = std::getenv("WHITTED_DATA_DIR"); dir && *dir) c.push_back(fs::path(dir) / relative);
    for (const fs::path& dir : {this_binary_dir(), executable_dir()}) {
        if (dir.empty()) continue;
        c.push_back(dir / "../share/whitted" / relative);        // <prefix>/lib or <prefix>/bin
        c.push_back(dir / "../../../share/whitted" / relative);  // <prefix>/lib/python3.X/site-packages
        c.push_back(dir / "../assets" / relative);              // build trees in or beside the source tree
        c.push_back(dir / "../../assets" / relative);
        c.push_back(dir / "../../../assets" / relative);
    }
#ifdef WHITTED_SOURCE_DIR
    c.push_back(fs::path(WHITTED_SOURCE_DIR) / "assets" / relative);  // the tree this was built from
#endif
    std::vector<std::string> out;
    for (const fs::path& p : c) {
        const std::string s = p.lexically_normal().string();
        bool seen = false;
        for (const std::string& o : out) seen = seen || o == s;
        if (!seen) out.push_back(s);
    }
    return out;
}

std::string data_file(const std::string& relative) {
    const std::vector<std::string> candidates = data_file_candidates(relative);
    for (const std::string& c : candidates) {
        std::error_code ec;
        if (fs::is_regular_file(c, ec)) return c;
    }
    throw Error(fmt::format("{} not found (looked in: {})", relative, fmt::join(candidates, ", ")));
}

}  // namespace whitted
