// Internal: the shading reduction as a CUDA kernel, for chunks whose words a
// GPU tracer left in device memory. One thread per vertex runs
// shading_from_words() of shading_hd.h, the very function the CPU runs, so the
// results have the same bits.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

#include "skybake/bake.h"

namespace skybake::bake {

struct ShadingResult {
    float ao = 0.0f, shading = 0.0f;
    glm::vec3 bent_normal{0.0f, 0.0f, 1.0f};
    std::uint32_t rays = 0, clamped = 0;
};

// Whether this build has the kernel (builds with CUDA).
bool shading_cuda_available();

// Reduces chunk.device_words into out[0 ... chunk.count). Throws
// skybake::Error on a CUDA failure, or in a build without CUDA.
void reduce_shading_cuda(const VisibilityRule& rule, const VisibilityChunk& chunk, bool normalize, ShadingResult* out);

} // namespace skybake::bake
