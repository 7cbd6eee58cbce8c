// Shared by the ambient-occlusion benchmarks (bench_ao, bench_gpu_ao): the
// scene kinds of their arguments and a wall-clock helper.
#pragma once

#include <chrono>

#include "skybake/mesh.h"

namespace skybake::bench {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Benchmark argument "kind": 0 city, 1 torus, 2 terrain.
inline ProceduralKind kind_of(int k) {
    return k == 0 ? ProceduralKind::City : k == 1 ? ProceduralKind::Torus : ProceduralKind::Terrain;
}

} // namespace skybake::bench
