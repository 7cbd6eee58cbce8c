// Deterministic random numbers: SplitMix64 (Steele, Lea & Flood, "Fast
// splittable pseudorandom number generators", OOPSLA 2014). The same bits on
// every machine, CPU and GPU alike (SKYBAKE_HD), and cheap to seed per index,
// so parallel loops stay independent of the thread count.
#pragma once

#include <cstdint>

#include "core/hd.h"

namespace skybake {

// The SplitMix64 output function of state z (a good 64-bit hash of z).
SKYBAKE_HD_INLINE std::uint64_t splitmix64(std::uint64_t z) {
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

// Uniform double in [0, 1) from the top 53 bits.
SKYBAKE_HD_INLINE double unit_double(std::uint64_t bits) { return double(bits >> 11) * (1.0 / 9007199254740992.0); }

// The generator: next() = splitmix64(state), then state advances by the golden gamma.
struct SplitMix64 {
    std::uint64_t state = 0;
    SKYBAKE_HD_INLINE std::uint64_t next() {
        const std::uint64_t r = splitmix64(state);
        state += 0x9e3779b97f4a7c15ull;
        return r;
    }
    SKYBAKE_HD_INLINE double uniform() { return unit_double(next()); } // [0, 1)
};

} // namespace skybake
