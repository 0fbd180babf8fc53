// A whole file's bytes in memory, in pages the kernel may back with transparent huge pages
// (private to importers/): read into ordinary 4 KiB pages, a large file costs a page fault per
// 4 KiB, which is most of its reading time on a virtual machine (docs/measurements/performance.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>

namespace whitted {

class FileBytes {
public:
    /// `size` bytes, uninitialised; throws std::bad_alloc when the memory cannot be mapped.
    explicit FileBytes(size_t size);
    ~FileBytes();
    FileBytes(const FileBytes&) = delete;
    FileBytes& operator=(const FileBytes&) = delete;
    FileBytes(FileBytes&& o) noexcept
        : m_mapping(std::exchange(o.m_mapping, nullptr)), m_mapped(std::exchange(o.m_mapped, 0)),
          m_data(std::exchange(o.m_data, nullptr)), m_size(std::exchange(o.m_size, 0)) {}
    FileBytes& operator=(FileBytes&&) = delete;

    uint8_t* data() { return m_data; }
    size_t size() const { return m_size; }
    std::span<const uint8_t> bytes() const { return {m_data, m_size}; }

private:
    void* m_mapping = nullptr;  ///< the anonymous mapping (nullptr when size is 0)
    size_t m_mapped = 0;        ///< its length
    uint8_t* m_data = nullptr;  ///< the first byte, aligned to a huge page inside the mapping
    size_t m_size = 0;
};

}  // namespace whitted
