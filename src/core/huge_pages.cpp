// restart_with_huge_pages: glibc reads GLIBC_TUNABLES once, at start-up, so the only way to set a
// tunable from inside is to start again with it.
#include "core/huge_pages.h"

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace whitted {

namespace {

constexpr const char* kTunable = "glibc.malloc.hugetlb=1";
/// Set for the second start: "-" when GLIBC_TUNABLES was unset before, else "=" and its value.
constexpr const char* kRestarted = "WHITTED_HUGE_PAGES_RESTARTED";
bool g_restarted = false;

/// The kernel's THP mode is "always" or "madvise" (not "never", and the file exists).
bool kernel_offers_huge_pages() {
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string line;
    if (!std::getline(in, line)) return false;
    return line.find("[always]") != std::string::npos || line.find("[madvise]") != std::string::npos;
}

/// The value GLIBC_TUNABLES gives glibc.malloc.hugetlb, or nullptr when it gives none.
const char* tunable_value() {
    constexpr const char* kName = "glibc.malloc.hugetlb=";
    const char* t = std::getenv("GLIBC_TUNABLES");
    const char* at = t != nullptr ? std::strstr(t, kName) : nullptr;
    return at != nullptr ? at + std::strlen(kName) : nullptr;
}

/// Runs that only print (--help, --version, no arguments) gain nothing from a second start.
bool only_prints(char** argv) {
    if (argv[0] == nullptr || argv[1] == nullptr) return true;
    for (char** a = argv + 1; *a != nullptr; ++a)
        if (std::strcmp(*a, "--help") == 0 || std::strcmp(*a, "-h") == 0 || std::strcmp(*a, "--version") == 0) return true;
    return false;
}

/// Every file named on the command line is a scene file (.json) under 1 MiB: a run that touches
/// a few megabytes, where huge pages cost more (2 MiB zeroed per first touch) than they save.
bool only_small_scene_files(char** argv) {
    bool any = false;
    for (char** a = argv + 1; *a != nullptr; ++a) {
        std::error_code ec;
        const std::filesystem::path p(*a);
        if (!std::filesystem::is_regular_file(p, ec)) continue;
        any = true;
        if (p.extension() != ".json" || std::filesystem::file_size(p, ec) >= (size_t(1) << 20) || ec) return false;
    }
    return any;
}

/// Under valgrind /proc/self/exe is the tool, not the program: never restart there.
bool under_valgrind() {
    const char* preload = std::getenv("LD_PRELOAD");
    return preload != nullptr && std::strstr(preload, "vgpreload") != nullptr;
}

}  // namespace

bool huge_pages_requested() {
    if (g_restarted) return true;
    const char* value = tunable_value();
    return value != nullptr && *value != '0';
}

void restart_with_huge_pages(char** argv) {
    // The second start: glibc has read the tunable; the environment goes back to what the user
    // gave, so that processes started from here (bench process, helpers) see it unchanged.
    if (const char* marker = std::getenv(kRestarted)) {
        g_restarted = true;
        const std::string before = marker;
        ::unsetenv(kRestarted);
        if (before.size() > 0 && before[0] == '=') ::setenv("GLIBC_TUNABLES", before.c_str() + 1, 1);
        else ::unsetenv("GLIBC_TUNABLES");
        return;
    }
    // The caller's own setting of the tunable (any value) stands.
    if (tunable_value() != nullptr || only_prints(argv) || only_small_scene_files(argv) || under_valgrind()) return;
    if (const char* opt = std::getenv("WHITTED_HUGE_PAGES"); opt != nullptr && std::strcmp(opt, "0") == 0) return;
    if (!kernel_offers_huge_pages()) return;
    const char* old = std::getenv("GLIBC_TUNABLES");
    const std::string tunables = (old != nullptr && old[0] != '\0') ? std::string(old) + ":" + kTunable : kTunable;
    const std::string saved = old != nullptr ? std::string("=") + old : std::string("-");
    if (::setenv(kRestarted, saved.c_str(), 1) != 0) return;
    if (::setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) {
        ::unsetenv(kRestarted);
        return;
    }
    ::execv("/proc/self/exe", argv);
    // exec failed: go on as we are, with the environment as it was.
    ::unsetenv(kRestarted);
    if (old != nullptr) ::setenv("GLIBC_TUNABLES", saved.c_str() + 1, 1);
    else ::unsetenv("GLIBC_TUNABLES");
}

}  // namespace whitted
