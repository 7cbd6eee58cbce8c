// GPU entry points of the neural sky that are not public API: the raw
// throughput measurement used by bench/bench_gpu_sky.cpp.
#pragma once

#include <cstdint>

#include "core/hd.h"
#include "skybake/neural.h"

namespace skybake::neural {

// The network inputs of sample k of the throughput measurement: a hash of k
// (Wellons' lowbias32), so the device generates them without transfers and a
// host loop can reproduce them. Not valid sky samples: the network does not care.
SKYBAKE_HD_INLINE float throughput_hash01(std::uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return float(x >> 8) * (1.0f / 16777216.0f);
}
SKYBAKE_HD_INLINE void throughput_inputs(std::uint32_t k, float in[4]) {
    in[0] = 2.0f * throughput_hash01(k) - 1.0f;
    in[1] = 2.0f * throughput_hash01(k + 0x9e3779b9U) - 1.0f;
    in[2] = 2.0f * throughput_hash01(k + 0x3c6ef372U) - 1.0f;
    in[3] = throughput_hash01(k + 0xdaa66d2bU);
}

struct GpuThroughput {
    double samples_per_second = 0.0;
    double seconds = 0.0;
    bool fixed_path = false; // the unrolled 4-8-4-1 kernel ran (else the generic one)
    double checksum = 0.0;   // Σ over the samples of r + g + b (float atomics), comparable with the CPU's
};

// Evaluates `samples` network outputs on device 0 with inputs generated on the
// device (no transfers), timed with CUDA events. Throws without a device.
GpuThroughput measure_neural_sky_cuda(const NeuralSky& net, std::uint64_t samples, bool force_generic = false);

} // namespace skybake::neural
