// CodeTable: the thresholds of a per-channel display transform, and the checks that it is one.
#include "output/code_table.h"

#include <array>

namespace whitted {

namespace {

/// Neighbours of each threshold compared with the transform (keys t - N .. t + N - 1).
constexpr uint32_t kNeighbours = 8;
/// Probes spread over the whole input range, compared with the transform.
constexpr uint32_t kProbes = 1u << 15;

}  // namespace

std::optional<CodeTable> CodeTable::build(const Evaluate& f, int bits) {
    const uint32_t max_code = bits == 16 ? 65535u : 255u;
    const float scale = float(max_code);
    const uint32_t key_lo = key(-kDisplayInputLimit), key_hi = key(kDisplayInputLimit);

    // Codes of all three channels at a list of keys per channel, through the transform.
    std::vector<float> rgb;
    auto codes_at = [&](const std::array<std::vector<uint32_t>, 3>& keys, std::array<std::vector<uint32_t>, 3>& codes) {
        const size_t n = keys[0].size();
        rgb.resize(3 * n);
        for (size_t j = 0; j < n; ++j)
            for (int c = 0; c < 3; ++c) rgb[3 * j + size_t(c)] = from_key(keys[size_t(c)][j]);
        f(rgb.data(), n);
        for (int c = 0; c < 3; ++c) {
            codes[size_t(c)].resize(n);
            for (size_t j = 0; j < n; ++j) codes[size_t(c)][j] = display_code(rgb[3 * j + size_t(c)], scale);
        }
    };

    // 1. Codes at every bucket start in the input range (and at its top): they must not decrease.
    const uint32_t first_bucket = key_lo >> kBucketShift, last_bucket = key_hi >> kBucketShift;
    std::array<std::vector<uint32_t>, 3> keys, codes;
    for (auto& k : keys) {
        k.clear();
        k.push_back(key_lo);
        for (uint32_t b = first_bucket + 1; b <= last_bucket; ++b) k.push_back(b << kBucketShift);
        k.push_back(key_hi);
    }
    codes_at(keys, codes);
    const std::array<std::vector<uint32_t>, 3> grid_keys = keys, grid_codes = codes;
    for (int c = 0; c < 3; ++c)
        for (size_t j = 1; j < grid_codes[size_t(c)].size(); ++j)
            if (grid_codes[size_t(c)][j] < grid_codes[size_t(c)][j - 1]) return std::nullopt;

    // 2. Each threshold k (the smallest key whose code is >= k) by bisection between the two grid
    //    keys around it, all thresholds of all channels at once.
    CodeTable table;
    std::array<std::vector<uint32_t>, 3> lo, hi;
    for (int c = 0; c < 3; ++c) {
        const auto& gk = grid_keys[size_t(c)];
        const auto& gc = grid_codes[size_t(c)];
        lo[size_t(c)].assign(max_code, 0);
        hi[size_t(c)].assign(max_code, 0);
        size_t g = 0;
        for (uint32_t k = 1; k <= max_code; ++k) {
            if (gc.front() >= k) {  // the lowest input already reaches k
                lo[size_t(c)][k - 1] = hi[size_t(c)][k - 1] = key_lo;
                continue;
            }
            if (gc.back() < k) {  // never reached: beyond every sanitised input
                lo[size_t(c)][k - 1] = hi[size_t(c)][k - 1] = key_hi + 1;
                continue;
            }
            while (gc[g + 1] < k) ++g;  // gc[g] < k <= gc[g + 1]
            lo[size_t(c)][k - 1] = gk[g];
            hi[size_t(c)][k - 1] = gk[g + 1];
        }
    }
    for (;;) {
        bool open = false;
        for (int c = 0; c < 3; ++c) {
            keys[size_t(c)].resize(max_code);
            for (uint32_t j = 0; j < max_code; ++j) {
                const uint32_t l = lo[size_t(c)][j], h = hi[size_t(c)][j];
                open |= h - l > 1;
                keys[size_t(c)][j] = h - l > 1 ? l + (h - l) / 2 : h;
            }
        }
        if (!open) break;
        codes_at(keys, codes);
        for (int c = 0; c < 3; ++c)
            for (uint32_t j = 0; j < max_code; ++j) {
                const uint32_t l = lo[size_t(c)][j], h = hi[size_t(c)][j];
                if (h - l <= 1) continue;
                (codes[size_t(c)][j] >= j + 1 ? hi : lo)[size_t(c)][j] = keys[size_t(c)][j];
            }
    }
    for (int c = 0; c < 3; ++c) {
        Channel& ch = table.m_channels[c];
        ch.thresholds = hi[size_t(c)];
        // Count of thresholds below each bucket's first key, for buckets 0 .. 2^16 (one past the last).
        ch.bucket_first.assign((size_t(1) << (32 - kBucketShift)) + 1, 0);
        size_t i = 0;
        for (size_t b = 0; b < ch.bucket_first.size(); ++b) {
            const uint64_t start = uint64_t(b) << kBucketShift;
            while (i < ch.thresholds.size() && ch.thresholds[i] < start) ++i;
            ch.bucket_first[b] = uint32_t(i);
        }
    }

    // 3. The table against the transform: around every threshold, and at probes spread over the
    //    whole range (plus the grid itself). One difference and the table is refused.
    auto agrees = [&](std::array<std::vector<uint32_t>, 3>& probe_keys) {
        codes_at(probe_keys, codes);
        for (int c = 0; c < 3; ++c)
            for (size_t j = 0; j < probe_keys[size_t(c)].size(); ++j)
                if (codes[size_t(c)][j] != table.code(c, from_key(probe_keys[size_t(c)][j]))) return false;
        return true;
    };
    auto clamp_key = [&](int64_t k) { return uint32_t(std::clamp<int64_t>(k, key_lo, key_hi)); };
    for (int c = 0; c < 3; ++c) {
        keys[size_t(c)].clear();
        for (uint32_t t : table.m_channels[c].thresholds)
            for (int64_t o = -int64_t(kNeighbours); o < int64_t(kNeighbours); ++o) keys[size_t(c)].push_back(clamp_key(int64_t(t) + o));
    }
    if (!agrees(keys)) return std::nullopt;
    for (int c = 0; c < 3; ++c) {
        keys[size_t(c)].clear();
        const uint64_t span = uint64_t(key_hi - key_lo);
        for (uint64_t j = 0; j < kProbes; ++j)  // channels probe different keys, so crosstalk would show
            keys[size_t(c)].push_back(clamp_key(int64_t(key_lo + span * (3 * j + uint64_t(c)) / (3 * kProbes))));
    }
    if (!agrees(keys)) return std::nullopt;
    keys = grid_keys;
    if (!agrees(keys)) return std::nullopt;
    return table;
}

}  // namespace whitted
