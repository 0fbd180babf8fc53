// Warnings grouped by kind (private to importers/): a file with 100000 faulty primitives gives
// one line per kind, "first message (and 99999 more like it)", not 100000 lines.
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include "scene/scene.h"

namespace whitted {

class WarningLog {
public:
    /// Records `message` under `kind`; only the first message of a kind is kept verbatim.
    void add(const std::string& kind, const std::string& message) {
        add(kind, message, 1);
    }

    /// Records every kind of `other` as if its messages were added here, in its order.
    void append(const WarningLog& other) {
        for (const Entry& e : other.m_entries) add(e.kind, e.first, e.count);
    }

    /// Moves every kind into scene.warnings, in first-seen order, and clears the log.
    void flush_to(Scene& scene) {
        for (const Entry& e : m_entries)
            scene.warn(e.count == 1 ? e.first : fmt::format("{} (and {} more like it)", e.first, e.count - 1));
        m_entries.clear();
        m_index.clear();
    }

private:
    struct Entry {
        std::string kind;
        std::string first;
        size_t count = 0;
    };

    void add(const std::string& kind, const std::string& message, size_t count) {
        auto [it, inserted] = m_index.emplace(kind, m_entries.size());
        if (inserted)
            m_entries.push_back({kind, message, count});
        else
            m_entries[it->second].count += count;
    }

    std::vector<Entry> m_entries;
    std::unordered_map<std::string, size_t> m_index;
};

}  // namespace whitted
