// The build without MPI: distributed.cpp compiled here without
// SKYBAKE_HAS_MPI (whatever this build has), so that every build tests the
// stub's one clear error. Its own executable: this file defines the module's
// functions, and the library's are not linked in.
#undef SKYBAKE_HAS_MPI
#include "distributed/distributed.cpp" // NOLINT: the stub variant of the module

#include <gtest/gtest.h>


namespace skybake {
namespace {

void expect_no_mpi(const std::function<void()>& f) {
    try {
        f();
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.message(), kNoMpiMessage);
        EXPECT_EQ(e.where(), "mpi");
    }
}

TEST(DistributedStub, EntryPointsThatNeedMpiThrowOneClearError) {
    EXPECT_FALSE(build_has_mpi());
    expect_no_mpi([] { join_job(); });
    expect_no_mpi([] { make_distributed_tracer(make_visibility_tracer("brute")); });
    EXPECT_FALSE(joined_job());
    EXPECT_EQ(job_rank().size, 1);
}

TEST(DistributedStub, TaskQueueRunsHereWithoutAJob) {
    std::vector<std::size_t> ran;
    const std::vector<std::string> r = run_task_queue(
        5, [&](std::size_t i) { ran.push_back(i); return i == 3 ? std::string("bad") : std::string(); }, "test");
    EXPECT_EQ(ran, (std::vector<std::size_t>{0, 1, 2, 3, 4}));
    ASSERT_EQ(r.size(), 5u);
    EXPECT_EQ(r[3], "bad");
    EXPECT_EQ(r[0], "");
    EXPECT_EQ(broadcast_from_root(42), 42);
}

TEST(DistributedStub, ErrorsPrintOneLineAndReturnTheCode) {
    testing::internal::CaptureStderr();
    EXPECT_EQ(finish_with_error("something broke (--rule)", 2), 2);
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_EQ(err, "skybake: error: something broke (--rule)\n");
}

} // namespace
} // namespace skybake
