// skybake/distributed.h: bakes spread over the processes of an MPI job
// (mpirun, srun). See docs/distributed.md.
//
// [SECTION] The job
// [SECTION] Distributed visibility
// [SECTION] Task queue
// [SECTION] Errors
//
// Every process ("rank") loads the scene and builds its own tracer. Rank 0
// keeps a queue of chunks of sample points; each rank (rank 0 too, on a
// thread of its own) asks for the next chunk when it has traced the last, so
// costly regions balance. The visibility words come back to rank 0, which
// runs the usual reduction over them in the usual order: the result is bit
// for bit that of one process with the same backend and flags. Only rank 0
// writes output.
//
// In a build without MPI (SKYBAKE_WITH_MPI=OFF, or no Open MPI found) the
// entry points that need MPI throw skybake::Error with the message of
// kNoMpiMessage (where: "mpi").
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "skybake/error.h"
#include "skybake/visibility.h"

namespace skybake {

// [SECTION] The job ---------------------------------------------------------------------

inline constexpr const char* kNoMpiMessage =
    "this skybake was built without MPI: configure with -DSKYBAKE_WITH_MPI=ON and install libopenmpi-dev";

// True when this build has MPI.
bool build_has_mpi();

// True when an MPI launcher started this process: one of the variables that
// Open MPI's mpirun (OMPI_COMM_WORLD_SIZE), PMI-1/2 (PMI_SIZE) or PMIx
// (PMIX_RANK, as Slurm's srun --mpi=pmix sets it) put in the environment.
bool launched_by_mpi();

// This process's place in the job.
struct JobRank {
    int rank = 0;       // 0 ... size − 1; rank 0 hands out work and writes output
    int size = 1;       // processes in the job
    int local_rank = 0; // index among the job's processes on this node (the GPU of a rank)
};

// Joins the MPI job (MPI_Init on the first call; MPI_Finalize at exit) and
// returns this process's rank. Outside a launcher, a job of one process.
// Throws skybake::Error (where: "mpi") in a build without MPI.
JobRank join_job();
// Whether join_job() has run; the rank, or {0, 1, 0} before.
bool joined_job();
JobRank job_rank();

// [SECTION] Distributed visibility ------------------------------------------------------

// What a distributed bake measured (rank 0; the last bake of this process).
struct DistributedStats {
    int ranks = 1;
    std::uint64_t chunks = 0;                   // handed out
    std::uint64_t points = 0;                   // sample points traced
    std::uint64_t bytes_gathered = 0;           // visibility words received from other ranks
    double trace_seconds = 0.0;                 // from the first chunk handed out to the last word in
    double gather_seconds = 0.0;                // rank 0's main thread receiving and copying words
    std::vector<std::uint64_t> points_per_rank; // one entry per rank
};

// A tracer for bake_visibility() (and so every bake on top of it) that
// spreads the bake's chunks over the job's ranks, each tracing with `local`
// (this rank's own tracer, already created: embree, brute, cuda on the
// rank's GPU). Every rank must run the same bake with the same inputs. On
// rank 0 the bake's reduction then sees every point's words; on the other
// ranks it sees zeros, and their results are to be discarded. Needs
// join_job() first; throws skybake::Error (where: "mpi") without MPI.
std::unique_ptr<VisibilityTracer> make_distributed_tracer(std::unique_ptr<VisibilityTracer> local);
// The measurements of the last distributed bake of this process.
DistributedStats last_distributed_stats();

// [SECTION] Task queue ------------------------------------------------------------------

// Runs tasks 0 ... count − 1 over the ranks from a queue on rank 0 (whole
// meshes of a batch bake, say): each rank takes the next task when it is
// done with the last. `task(i)` returns a short text (empty for success);
// it must not throw for the failure of one task (catch and return the
// message). Returns, on rank 0, every task's text in task order; on other
// ranks an empty vector. Without join_job(), runs every task here. `label`
// names the progress bar on rank 0.
std::vector<std::string> run_task_queue(std::size_t count, const std::function<std::string(std::size_t)>& task,
                                        const std::string& label);

// Broadcasts an integer from rank 0 to every rank (without a job: returns it).
std::int64_t broadcast_from_root(std::int64_t value);

// [SECTION] Errors ----------------------------------------------------------------------
//
// A rank that fails ends the whole job: every rank exits non-zero and one
// line is printed. finish_with_error() is that path (the CLI calls it for
// every error it prints): without a job it prints `line` to stderr and
// returns `code`. In a job of several ranks, rank 0 prints and aborts the
// job with `code`; another rank sends its line to rank 0, which prints it
// (naming the rank) and aborts; if rank 0 does not answer within a few
// seconds (it is busy loading, say) the rank prints its line itself and
// aborts. Does not return then.
int finish_with_error(const std::string& line, int code);

// An error that every rank of the job raises together, having agreed on it
// (the failures of a batch): rank 0 prints it, the others stay silent, and
// every rank ends MPI normally and exits with the code.
class JobError : public Error {
public:
    using Error::Error;
};
// As finish_with_error() for a JobError.
int finish_with_job_error(const std::string& line, int code);

// Test hook: throws skybake::Error when the environment asks this rank to
// fail at `stage` ("load": after loading the scene; "chunk": after its first
// traced chunk): SKYBAKE_TEST_MPI_FAIL_RANK=K and SKYBAKE_TEST_MPI_FAIL_AT=stage
// (default "chunk"); SKYBAKE_TEST_MPI_FAIL_AT=kill: the rank kills itself
// (SIGKILL) after its first chunk.
void test_fault_point(const char* stage);

} // namespace skybake
