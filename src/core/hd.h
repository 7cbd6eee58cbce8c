// SKYBAKE_HD marks maths shared by the CPU and the GPU (pbrt-v4's PBRT_CPU_GPU).
// Under nvcc it expands to __host__ __device__; elsewhere to nothing, so the
// same function is unit-tested on the CPU and run unchanged in CUDA kernels.
#pragma once

#if defined(__CUDACC__)
#define SKYBAKE_HD __host__ __device__
#define SKYBAKE_HD_INLINE __host__ __device__ __forceinline__
#else
#define SKYBAKE_HD
#define SKYBAKE_HD_INLINE inline
#endif
