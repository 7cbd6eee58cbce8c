// Parallel loops over index ranges, on oneTBB.
//
// Results must not depend on the number of threads: callers write per-index
// results, or reduce per-chunk partials in chunk order (parallel_reduce_chunks).
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

namespace skybake {

// Calls body(begin, end) over disjoint sub-ranges covering [0, count).
// grain: smallest sub-range worth a task.
void parallel_for(std::size_t count, std::size_t grain,
                  const std::function<void(std::size_t begin, std::size_t end)>& body);

// Deterministic reduction: [0, count) is cut into fixed chunks of `chunk`
// indices; body(begin, end) returns the chunk's partial, and partials are
// combined in chunk order, whatever the thread count.
template <class T, class Body, class Combine>
T parallel_reduce_chunks(std::size_t count, std::size_t chunk, T init, Body body, Combine combine) {
    if (chunk == 0)
        chunk = 1;
    const std::size_t chunks = (count + chunk - 1) / chunk;
    std::vector<T> partial(chunks, init);
    parallel_for(chunks, 1, [&](std::size_t b, std::size_t e) {
        for (std::size_t c = b; c < e; ++c) {
            const std::size_t lo = c * chunk;
            const std::size_t hi = lo + chunk < count ? lo + chunk : count;
            partial[c] = body(lo, hi);
        }
    });
    T result = init;
    for (const T& p : partial)
        result = combine(result, p);
    return result;
}

} // namespace skybake
