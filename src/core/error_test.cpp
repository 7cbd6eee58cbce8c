#include <gtest/gtest.h>

#include <cmath>

#include "core/parallel.h"
#include "skybake/core.h"
#include "skybake/error.h"

using namespace skybake;

TEST(Error, OneLineWithLocation) {
    Error e("bad index 7\nin face 3", "mesh.obj");
    EXPECT_STREQ(e.what(), "bad index 7 in face 3 (mesh.obj)");
    EXPECT_EQ(e.message(), "bad index 7\nin face 3");
    EXPECT_EQ(e.where(), "mesh.obj");
}

TEST(Error, WithoutLocation) { EXPECT_STREQ(Error("no triangles").what(), "no triangles"); }

TEST(Parallel, ReduceIsIndependentOfThreadCount) {
    // Floating-point sums depend on order; chunked reduction must not.
    auto run = [](int threads) {
        set_thread_count(threads);
        double s = parallel_reduce_chunks<double>(
            1000003, 4096, 0.0,
            [](std::size_t b, std::size_t e) {
                double a = 0;
                for (std::size_t i = b; i < e; ++i)
                    a += 1.0 / double(i + 1);
                return a;
            },
            [](double a, double b) { return a + b; });
        set_thread_count(0);
        return s;
    };
    const double one = run(1), two = run(2);
    EXPECT_EQ(one, two); // bit-identical
    EXPECT_NEAR(one, std::log(1000003.0) + 0.5772156649, 1e-6);
}

TEST(Parallel, CoversRangeOnce) {
    std::vector<int> hits(100000, 0);
    parallel_for(hits.size(), 64, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i)
            hits[i]++;
    });
    for (int h : hits)
        ASSERT_EQ(h, 1);
}
