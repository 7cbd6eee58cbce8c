// Small CUDA helpers for the .cu files: error checks that throw
// skybake::Error, and an owning device buffer. Include only from .cu files.
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

#include <cuda_runtime.h>

#include "skybake/error.h"

namespace skybake::cuda {

inline void check(cudaError_t e, const char* what) {
    if (e != cudaSuccess) {
        cudaGetLastError(); // clear a sticky launch error
        throw Error(std::string("CUDA error: ") + cudaGetErrorString(e) + " in " + what, "CUDA");
    }
}

#define SKYBAKE_CUDA_CHECK(expr) ::skybake::cuda::check((expr), #expr)

// Owning, non-copyable device array of T.
template <class T>
class DeviceBuffer {
public:
    DeviceBuffer() = default;
    explicit DeviceBuffer(std::size_t n) { resize(n); }
    ~DeviceBuffer() { release(); }
    DeviceBuffer(const DeviceBuffer&) = delete;
    DeviceBuffer& operator=(const DeviceBuffer&) = delete;
    DeviceBuffer(DeviceBuffer&& o) noexcept : ptr_(o.ptr_), size_(o.size_) { o.ptr_ = nullptr, o.size_ = 0; }

    void resize(std::size_t n) {
        if (n == size_)
            return;
        release();
        if (n > 0)
            SKYBAKE_CUDA_CHECK(cudaMalloc(reinterpret_cast<void**>(&ptr_), n * sizeof(T)));
        size_ = n;
    }
    void upload(const T* src, std::size_t n, cudaStream_t stream = nullptr) {
        resize(n);
        if (n > 0)
            SKYBAKE_CUDA_CHECK(cudaMemcpyAsync(ptr_, src, n * sizeof(T), cudaMemcpyHostToDevice, stream));
    }
    // Copies n ≤ size() elements into the start of the buffer, keeping its size
    // (upload() resizes to n).
    void upload_prefix(const T* src, std::size_t n, cudaStream_t stream = nullptr) {
        if (n > 0)
            SKYBAKE_CUDA_CHECK(
                cudaMemcpyAsync(ptr_, src, std::min(n, size_) * sizeof(T), cudaMemcpyHostToDevice, stream));
    }
    void download(T* dst, std::size_t n, cudaStream_t stream = nullptr) const {
        if (n > 0)
            SKYBAKE_CUDA_CHECK(cudaMemcpyAsync(dst, ptr_, n * sizeof(T), cudaMemcpyDeviceToHost, stream));
    }
    T* data() { return ptr_; }
    const T* data() const { return ptr_; }
    std::size_t size() const { return size_; }

private:
    void release() {
        if (ptr_)
            cudaFree(ptr_);
        ptr_ = nullptr;
        size_ = 0;
    }
    T* ptr_ = nullptr;
    std::size_t size_ = 0;
};

// Blocks for n threads of `block` threads each.
inline unsigned grid_for(std::size_t n, unsigned block) { return unsigned((n + block - 1) / block); }

} // namespace skybake::cuda
