#include "importers/file_bytes.h"

#include <new>

#include <sys/mman.h>

namespace whitted {

namespace {

constexpr size_t kHugePage = size_t(2) << 20;  ///< x86-64 transparent huge page

}  // namespace

FileBytes::FileBytes(size_t size) : m_size(size) {
    if (size == 0) return;
    // Small files get ordinary pages; larger ones a huge-page-aligned range the kernel is asked to
    // back with huge pages (a hint: with THP off they are 4 KiB pages, as before).
    const bool huge = size >= kHugePage;
    const size_t rounded = huge ? (size + kHugePage - 1) / kHugePage * kHugePage : size;
    m_mapped = huge ? rounded + kHugePage : rounded;
    m_mapping = mmap(nullptr, m_mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m_mapping == MAP_FAILED) {
        m_mapping = nullptr;
        throw std::bad_alloc();
    }
    const uintptr_t start = reinterpret_cast<uintptr_t>(m_mapping);
    m_data = reinterpret_cast<uint8_t*>(huge ? (start + kHugePage - 1) / kHugePage * kHugePage : start);
    if (huge) madvise(m_data, rounded, MADV_HUGEPAGE);  // best effort
}

FileBytes::~FileBytes() {
    if (m_mapping != nullptr) munmap(m_mapping, m_mapped);
}

}  // namespace whitted
