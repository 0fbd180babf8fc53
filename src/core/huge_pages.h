// Transparent huge pages for the whole process, through glibc's malloc.
#pragma once

namespace whitted {

/// Re-executes the running program (/proc/self/exe, same argv and environment) with
/// GLIBC_TUNABLES gaining glibc.malloc.hugetlb=1, so that malloc asks the kernel for transparent
/// huge pages: a large buffer then faults in 2 MiB at a time instead of 4 KiB. Does nothing and
/// returns when the kernel offers no transparent huge pages, when GLIBC_TUNABLES already sets
/// the tunable (to any value), when WHITTED_HUGE_PAGES=0, under valgrind, for runs that only print (--help,
/// --version, no arguments), for runs whose only files are scene files (.json) under 1 MiB (they
/// touch a few megabytes: 2 MiB pages would cost more than they save), or when exec fails. In the restarted process it puts GLIBC_TUNABLES
/// back as the user gave it (glibc has read it by then), so processes it starts inherit the
/// user's environment. Call first thing in main(), before any thread or library state exists.
void restart_with_huge_pages(char** argv);

/// Whether this process runs with glibc.malloc.hugetlb set to a non-zero value (by
/// restart_with_huge_pages or by the caller's own GLIBC_TUNABLES).
bool huge_pages_requested();

}  // namespace whitted
