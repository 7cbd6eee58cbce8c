// The CUDA network against the CPU inference. Skips without a GPU.
// Metric: per lit sample, |gpu − cpu| over the CPU's largest channel, within a
// forward error bound modelled from the network's weights (see below).
#include <algorithm>
#include <array>
#include <cstdio>
#include <string>
#include <vector>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "neural/error_bound_test_util.h"
#include "neural/neural_cuda.h"
#include "skybake/core.h"
#include "skybake/error.h"
#include "skybake/neural.h"
#include "core/gpu_test.h"

using namespace skybake;

using namespace skybake::neural_test;

TEST(NeuralCuda, WithoutADeviceTheErrorIsClear) {
    if (cuda_device_count() > 0)
        GTEST_SKIP() << "a CUDA device is present";
    const NeuralSky net = random_network("paper", 1);
    std::vector<SkySample> s(4);
    std::vector<glm::vec3> out(4);
    EXPECT_THROW(evaluate_neural_sky_cuda(net, s, out), Error);
    EXPECT_THROW(neural::measure_neural_sky_cuda(net, 1000), Error);
}

TEST(NeuralCuda, SeedTopologyMatchesTheCpu) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    for (unsigned seed : {1u, 2u, 3u}) {
        const NeuralSky net = random_network("paper", seed);
        const auto samples = draw_sky_samples(100000, seed);
        std::vector<glm::vec3> cpu(samples.size()), gpu(samples.size());
        evaluate_neural_sky(net, samples, cpu);
        evaluate_neural_sky_cuda(net, samples, gpu);
        SCOPED_TRACE("seed " + std::to_string(seed));
        expect_within_modelled_bound(net, samples, cpu, gpu);
    }
}

TEST(NeuralCuda, GenericTopologiesMatchTheCpu) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    // 16x16 fits constant memory; shared:128x128x128 (about 33k weights) does not.
    for (const char* topology : {"independent:16x16", "shared:32x32", "shared:128x128x128"}) {
        const NeuralSky net = random_network(topology, 5);
        const auto samples = draw_sky_samples(20000, 9);
        std::vector<glm::vec3> cpu(samples.size()), gpu(samples.size());
        evaluate_neural_sky(net, samples, cpu);
        evaluate_neural_sky_cuda(net, samples, gpu);
        SCOPED_TRACE(topology);
        expect_within_modelled_bound(net, samples, cpu, gpu);
    }
}

TEST(NeuralCuda, EveryEncodingMatchesTheCpu) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    const auto compare = [](const NeuralSky& net, std::uint64_t seed, const std::string& what) {
        const auto samples = draw_sky_samples(50000, seed);
        std::vector<glm::vec3> cpu(samples.size()), gpu(samples.size());
        evaluate_neural_sky(net, samples, cpu);
        evaluate_neural_sky_cuda(net, samples, gpu);
        SCOPED_TRACE(what);
        expect_within_modelled_bound(net, samples, cpu, gpu);
    };
    for (InputEncoding inputs : {InputEncoding::Seed, InputEncoding::Horizon})
        for (OutputEncoding outputs : {OutputEncoding::Radiance, OutputEncoding::PhaseFactored, OutputEncoding::Residual})
            for (const char* topology : {"paper", "shared:16x12"}) {
                if (outputs != OutputEncoding::Radiance && std::string(topology) == "paper")
                    continue; // independent sub-networks have one output each: 6 of them here, not the seed's 4
                compare(with_encoding(random_network(topology, 4), inputs, outputs, 12), 21,
                        std::string(topology) + ", " + input_encoding_name(inputs) + " / " +
                            output_encoding_name(outputs));
            }
    // Multiple scattering, its term a correction of the isotropic march.
    compare(with_marched_multiple(with_encoding(random_network("shared:16x12", 4), InputEncoding::Horizon,
                                                OutputEncoding::Residual, 12, true)),
            23, "shared:16x12, multiple scattering marched");
    // An aerosol family: the fifth input and the scaled, Chapman-view march.
    compare(with_family(with_encoding(random_network("shared:16x12", 4), InputEncoding::Horizon,
                                      OutputEncoding::Residual, 12),
                        1.0, 32.0, 9.0, 13),
            22, "shared:16x12, aerosol family at 9");
}

TEST(NeuralCuda, ThroughputChecksumEqualsTheCpus) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    // The throughput kernel's inputs are reproducible on the host
    // (throughput_inputs): the sum of r + g + b over them from the CPU
    // inference, in double, against the GPU's float atomics. Float summation of
    // 2^20 terms and the fast activation put ~1e-5 relative between them; a
    // kernel that skips work, reads the wrong weights or sums twice is off by
    // far more than 1e-3.
    const std::uint64_t n = 1 << 20;
    for (bool generic : {false, true}) {
        const NeuralSky net = random_network("paper", 1);
        const auto t = neural::measure_neural_sky_cuda(net, n, generic);
        EXPECT_EQ(t.fixed_path, !generic);
        EXPECT_GT(t.samples_per_second, 0.0);
        std::vector<SkySample> s(n);
        for (std::uint32_t k = 0; k < n; ++k) {
            float in[4];
            neural::throughput_inputs(k, in);
            s[k] = SkySample{in[0], in[1], in[2], in[3]};
        }
        std::vector<glm::vec3> cpu(n);
        evaluate_neural_sky(net, s, cpu);
        double sum = 0.0;
        for (const glm::vec3& c : cpu)
            sum += double(c.x) + double(c.y) + double(c.z);
        ASSERT_GT(sum, 0.0);
        EXPECT_NEAR(t.checksum, sum, 1e-3 * sum) << (generic ? "generic" : "fixed") << " kernel";
    }
}
