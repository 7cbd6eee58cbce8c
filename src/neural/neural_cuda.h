// GPU entry points of the neural sky that are not public API: the raw
// throughput measurement used by bench/bench_gpu_sky.cpp.
#pragma once

#include <cstdint>

#include "skybake/neural.h"

namespace skybake::neural {

struct GpuThroughput {
    double samples_per_second = 0.0;
    double seconds = 0.0;
    bool fixed_path = false; // the unrolled 4-8-4-1 kernel ran (else the generic one)
    double checksum = 0.0;   // keeps the work observable
};

// Evaluates `samples` network outputs on device 0 with inputs generated on the
// device (no transfers), timed with CUDA events. Throws without a device.
GpuThroughput measure_neural_sky_cuda(const NeuralSky& net, std::uint64_t samples, bool force_generic = false);

} // namespace skybake::neural
