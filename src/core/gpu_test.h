// For GPU tests (*_gpu_test.cpp/.cu): skip without a usable CUDA device and say
// why (no GPU, no driver, a driver mismatch...). With SKYBAKE_REQUIRE_GPU=1 in
// the environment (scripts/gpu-check.sh sets it) the missing device is a
// failure instead, so that a broken machine cannot pass by skipping.
#pragma once

#include <cstdlib>
#include <cstring>

#include <gtest/gtest.h>

#include "skybake/core.h"

namespace skybake::test {

inline bool gpu_required() {
    const char* v = std::getenv("SKYBAKE_REQUIRE_GPU");
    return v && *v && std::strcmp(v, "0") != 0;
}

} // namespace skybake::test

#define SKYBAKE_SKIP_WITHOUT_GPU()                                                                                     \
    do {                                                                                                               \
        if (::skybake::cuda_device_count() == 0) {                                                                     \
            if (::skybake::test::gpu_required())                                                                       \
                FAIL() << "SKYBAKE_REQUIRE_GPU is set, but no CUDA device is usable: "                                 \
                       << ::skybake::cuda_device_problem();                                                            \
            GTEST_SKIP() << "no CUDA device: " << ::skybake::cuda_device_problem();                                    \
        }                                                                                                              \
    } while (0)
