// The CLI's side of a distributed bake (skybake/distributed.h): whether this
// run is one rank of an MPI job, and what only rank 0 does.
#pragma once

#include <memory>

#include "skybake/core.h"
#include "skybake/distributed.h"
#include "skybake/visibility.h"

namespace skybake::cli {

// A bake runs as an MPI job when an MPI launcher started it (mpirun, srun)
// or --mpi asks for one. Joins the job first, so that every later error is
// reported once for the whole job; other ranks than 0 are quiet. Without
// MPI in the build: skybake::Error (kNoMpiMessage). Returns whether this is
// a job.
inline bool start_job(bool mpi_flag) {
    if (!mpi_flag && !launched_by_mpi())
        return false;
    const JobRank r = join_job();
    if (r.rank != 0)
        set_quiet(true);
    return true;
}

// Whether this process writes output and reports: rank 0, or not a job.
inline bool job_root() {
    return job_rank().rank == 0;
}

// In a job, the tracer that spreads the bake over the ranks; else `local`.
inline std::unique_ptr<VisibilityTracer> job_tracer(std::unique_ptr<VisibilityTracer> local, bool job) {
    return job ? make_distributed_tracer(std::move(local)) : std::move(local);
}

} // namespace skybake::cli
