// Distributed bakes: a master queue over chunks of sample points on rank 0
// (dynamic self-scheduling: a rank asks for the next chunk when it has
// returned the last), and the words gathered to rank 0. The only file that
// includes mpi.h; without MPI its entry points throw kNoMpiMessage.
//
// Protocol (MPI_COMM_WORLD, point to point only):
//   rank k → 0  result tag  int64 task (−1 on the first request), then the task's result bytes
//   0 → rank k  assign tag  int64 the next task, or −1: no more
//   rank k → 0  kTagError   int32 exit code, then the error line; rank 0 prints it and aborts the job
// Every rank runs the same sequence of queues; the result and assign tags
// carry the queue's number, so that a rank that has moved on to the next
// queue is not served by rank 0's loop of the last one.
#include "skybake/distributed.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "core/progress.h"
#include "skybake/bake.h"
#include "skybake/core.h"
#include "skybake/interrupt.h"

#if defined(SKYBAKE_HAS_MPI)
#define OMPI_SKIP_MPICXX 1 // the C API only
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace skybake {

namespace {

// Chunks of a distributed bake: at least this many per rank (so that a slow
// region does not hold up the end), each at most kChunkRays rays on a CPU
// tracer and at most kChunkWordBytes of words, and no smaller than kMinChunk
// points.
constexpr std::uint32_t kChunksPerRank = 8;
constexpr std::uint64_t kChunkRays = std::uint64_t(1) << 23;
constexpr std::uint64_t kChunkWordBytes = std::uint64_t(64) << 20;
constexpr std::uint32_t kMinChunk = 256;

JobRank g_rank;
bool g_joined = false;
DistributedStats g_stats;
std::uint64_t g_queue = 0; // queues run so far (every rank runs the same sequence)

// The rank an MPI launcher gave this process, read from the environment
// (before or without MPI_Init); -1 when there is none.
int launcher_rank() {
    for (const char* v : {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"})
        if (const char* s = std::getenv(v))
            return std::atoi(s);
    return -1;
}

void print_line(const std::string& line) {
    std::fprintf(stderr, "skybake: error: %s\n", line.c_str());
    std::fflush(stderr);
}

// One task of a queue: runs on any rank (rank 0: on a thread of its own).
using TaskWork = std::function<std::vector<char>(std::size_t task)>;
// Rank 0, main thread: a task's result arrived from `rank`.
using TaskCollect = std::function<void(std::size_t task, int rank, const char* data, std::size_t bytes)>;
using TaskWeight = std::function<std::uint64_t(std::size_t task)>;

void nap() {
    std::this_thread::sleep_for(std::chrono::microseconds(200));
}

#if defined(SKYBAKE_HAS_MPI)

constexpr int kTagError = 1;
// The tags of queue number `queue` (MPI guarantees tags up to 32767).
int result_tag(std::uint64_t queue) {
    return 10 + 2 * int(queue % 16000);
}
int assign_tag(std::uint64_t queue) {
    return 11 + 2 * int(queue % 16000);
}

void finalize_at_exit() {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized)
        MPI_Finalize();
}

// Rank 0 received an error line from another rank: print it and end the job.
[[noreturn]] void relay_error(const MPI_Status& st) {
    int bytes = 0;
    MPI_Get_count(&st, MPI_BYTE, &bytes);
    std::vector<char> msg(std::size_t(std::max(bytes, 4)), 0);
    MPI_Recv(msg.data(), bytes, MPI_BYTE, st.MPI_SOURCE, kTagError, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    std::int32_t code = 1;
    std::memcpy(&code, msg.data(), 4);
    print_line(fmt::format("rank {} of {}: {}", st.MPI_SOURCE, g_rank.size,
                           std::string(msg.data() + 4, msg.data() + std::max(bytes, 4))));
    MPI_Abort(MPI_COMM_WORLD, code ? code : 1);
    std::abort();
}

// Ranks other than 0: ask, work, return, until the queue is empty.
void work_for_root(const TaskWork& work) {
    const int tag_result = result_tag(g_queue), tag_assign = assign_tag(g_queue);
    std::vector<char> message(8);
    std::int64_t done = -1;
    std::memcpy(message.data(), &done, 8);
    for (;;) {
        MPI_Send(message.data(), int(message.size()), MPI_BYTE, 0, tag_result, MPI_COMM_WORLD);
        std::int64_t task = -1;
        MPI_Request request;
        MPI_Irecv(&task, 1, MPI_INT64_T, 0, tag_assign, MPI_COMM_WORLD, &request);
        for (int flag = 0;;) {
            MPI_Test(&request, &flag, MPI_STATUS_IGNORE);
            if (flag)
                break;
            check_interrupted();
            nap();
        }
        if (task < 0) {
            ++g_queue;
            return;
        }
        const std::vector<char> r = work(std::size_t(task));
        if (r.size() > std::size_t(0x7fffffff) - 8)
            throw Error(fmt::format("a chunk of {} bytes is too large for one message", r.size()), "mpi");
        message.resize(8 + r.size());
        std::memcpy(message.data(), &task, 8);
        std::copy(r.begin(), r.end(), message.begin() + 8);
    }
}

#endif // SKYBAKE_HAS_MPI

// Rank 0's side of a queue (and the whole of it without a job): hands out
// tasks to the other ranks and to a thread of its own, and collects their
// results on the calling thread, the one that calls MPI, whenever it pumps.
class Queue {
public:
    Queue(std::size_t count, TaskWork work, TaskCollect collect, TaskWeight weight, Progress* progress)
        : count_(count), work_(std::move(work)), collect_(std::move(collect)), weight_(std::move(weight)),
          progress_(progress), active_(g_joined ? g_rank.size - 1 : 0) {
#if defined(SKYBAKE_HAS_MPI)
        tag_result_ = result_tag(g_queue);
        tag_assign_ = assign_tag(g_queue);
#endif
        local_ = std::thread([this] { run_local(); });
    }
    ~Queue() {
        stop_ = true;
        if (local_.joinable())
            local_.join();
    }
    Queue(const Queue&) = delete;
    Queue& operator=(const Queue&) = delete;

    // Collects what has come in (the local thread's results, one message of
    // another rank) and answers that rank. Returns whether anything came.
    // Throws the local thread's error.
    bool pump() {
        bool busy = false;
        std::deque<std::pair<std::size_t, std::vector<char>>> done;
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            if (local_error_)
                std::rethrow_exception(local_error_);
            done.swap(local_done_);
        }
        for (auto& [t, r] : done) {
            collect_(t, 0, r.data(), r.size());
            if (progress_)
                progress_->advance(weight_(t));
            busy = true;
        }
#if defined(SKYBAKE_HAS_MPI)
        if (g_joined) {
            int flag = 0;
            MPI_Status st;
            MPI_Iprobe(MPI_ANY_SOURCE, kTagError, MPI_COMM_WORLD, &flag, &st);
            if (flag)
                relay_error(st);
            MPI_Iprobe(MPI_ANY_SOURCE, tag_result_, MPI_COMM_WORLD, &flag, &st);
            if (flag) {
                busy = true;
                const auto t0 = std::chrono::steady_clock::now();
                int bytes = 0;
                MPI_Get_count(&st, MPI_BYTE, &bytes);
                buffer_.resize(std::size_t(bytes));
                MPI_Recv(buffer_.data(), bytes, MPI_BYTE, st.MPI_SOURCE, tag_result_, MPI_COMM_WORLD,
                         MPI_STATUS_IGNORE);
                std::int64_t task = -1;
                std::memcpy(&task, buffer_.data(), sizeof task);
                if (task >= 0) {
                    collect_(std::size_t(task), st.MPI_SOURCE, buffer_.data() + 8, buffer_.size() - 8);
                    if (progress_)
                        progress_->advance(weight_(std::size_t(task)));
                }
                gather_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
                std::int64_t assign = -1;
                if (!stop_) {
                    const std::size_t t = next_++;
                    if (t < count_)
                        assign = std::int64_t(t);
                }
                MPI_Send(&assign, 1, MPI_INT64_T, st.MPI_SOURCE, tag_assign_, MPI_COMM_WORLD);
                if (assign < 0)
                    --active_;
            }
        }
#endif
        return busy;
    }
    // Pumps until every task is in and every rank has been told that the
    // queue is empty.
    void finish() {
        for (;;) {
            bool idle_here;
            {
                const std::lock_guard<std::mutex> lock(mutex_);
                idle_here = local_finished_ && local_done_.empty() && !local_error_;
            }
            if (idle_here && active_ == 0)
                break;
            if (!pump()) {
                check_interrupted();
                nap();
            }
        }
        local_.join();
        if (local_error_)
            std::rethrow_exception(local_error_);
        ++g_queue;
    }

    double gather_seconds = 0.0; // receiving and collecting other ranks' results

private:
    void run_local() {
        try {
            use_cuda_device_on_this_thread();
            while (!stop_) {
                const std::size_t t = next_++;
                if (t >= count_)
                    break;
                std::vector<char> r = work_(t);
                const std::lock_guard<std::mutex> lock(mutex_);
                local_done_.emplace_back(t, std::move(r));
            }
        } catch (...) {
            const std::lock_guard<std::mutex> lock(mutex_);
            local_error_ = std::current_exception();
        }
        const std::lock_guard<std::mutex> lock(mutex_);
        local_finished_ = true;
    }

    std::size_t count_;
    TaskWork work_;
    TaskCollect collect_;
    TaskWeight weight_;
    Progress* progress_;
    int active_; // other ranks not yet told that the queue is empty
    int tag_result_ = 0, tag_assign_ = 0;
    std::atomic<std::size_t> next_{0};
    std::atomic<bool> stop_{false};
    std::mutex mutex_;
    bool local_finished_ = false;
    std::deque<std::pair<std::size_t, std::vector<char>>> local_done_;
    std::exception_ptr local_error_;
    std::vector<char> buffer_;
    std::thread local_;
};

// Runs a queue over the job (or here, without one), to the end.
void run_queue(std::size_t count, const TaskWork& work, const TaskCollect& collect, const TaskWeight& weight,
               const std::string& label, std::uint64_t total_weight, double& gather_seconds) {
#if defined(SKYBAKE_HAS_MPI)
    if (g_joined && g_rank.rank != 0) {
        work_for_root(work);
        return;
    }
#endif
    Progress progress(label, total_weight);
    Queue queue(count, work, collect, weight, &progress);
    queue.finish();
    progress.finish();
    gather_seconds += queue.gather_seconds;
}

// The tracer behind make_distributed_tracer().
class DistributedTracer final : public WholeBakeTracer {
public:
    explicit DistributedTracer(std::unique_ptr<VisibilityTracer> local) : local_(std::move(local)) {}

    const char* name() const override { return local_->name(); }
    TraceMethod method() const override { return local_->method(); }
    std::string device_name() const override { return local_->device_name(); }
    void set_mesh(const Mesh& mesh, BackFaces back_faces) override { local_->set_mesh(mesh, back_faces); }
    std::uint32_t set_rule(const TraceRule& rule) override {
        words_per_point_ = rule.words_per_vertex;
        directions_ = std::max<std::size_t>(1, rule.points.size());
        local_limit_ = std::max<std::uint32_t>(1, local_->set_rule(rule));
        // The driver's chunks read the words back as they arrive: as small as
        // a CPU bake's, so that its reduction follows the tracing closely.
        return std::uint32_t(std::max<std::uint64_t>(kMinChunk, kChunkRays / directions_));
    }
    bool prefers_large_chunks() const override { return true; }

    // Starts the queue over the points' chunks. Rank 0 (or no job) returns at
    // once: trace() then collects chunks while the driver reduces the ones
    // before, so that the reduction overlaps the tracing of the rest. The
    // other ranks trace their share here and return when the queue is empty.
    void trace_points(std::uint32_t n, const ChunkBuilder& build) override {
        const int ranks = g_joined ? g_rank.size : 1;
        const std::uint32_t w = words_per_point_;
        // Chunks: as the single-process driver sizes them for a CPU tracer
        // (rays per chunk) or a GPU tracer (its limit), but enough of them for
        // every rank to take several.
        const std::uint64_t by_rays = std::max<std::uint64_t>(kMinChunk, kChunkRays / directions_);
        const std::uint64_t wanted = local_->prefers_large_chunks() ? local_limit_ : by_rays;
        const std::uint64_t spread = std::max<std::uint64_t>(kMinChunk, n / (std::uint64_t(ranks) * kChunksPerRank));
        const std::uint64_t by_bytes = std::max<std::uint64_t>(1, kChunkWordBytes / (4ull * std::max(w, 1u)));
        n_ = n;
        chunk_ = std::uint32_t(std::max<std::uint64_t>(
            1, std::min({wanted, spread, by_bytes, std::uint64_t(local_limit_), std::uint64_t(std::max(n, 1u))})));
        const std::size_t chunks = n == 0 ? 0 : (std::size_t(n) + chunk_ - 1) / chunk_;
        build_ = build;
        traced_here_ = 0;
        stats_ = DistributedStats{};
        stats_.ranks = ranks;
        stats_.chunks = chunks;
        stats_.points = n;
        stats_.points_per_rank.assign(std::size_t(ranks), 0);
        start_ = std::chrono::steady_clock::now();
        const TaskWork work = [this](std::size_t t) { return trace_task(t); };
#if defined(SKYBAKE_HAS_MPI)
        if (g_joined && g_rank.rank != 0) {
            words_.clear();
            work_for_root(work);
            finish_stats();
            return;
        }
#endif
        words_.assign(std::size_t(n) * w, 0u);
        arrived_.assign(chunks, 0);
        const TaskCollect collect = [this](std::size_t t, int rank, const char* data, std::size_t bytes) {
            const auto [first, count] = range(t);
            const std::size_t want = std::size_t(count) * words_per_point_ * 4;
            if (bytes != want)
                throw Error(fmt::format("rank {} returned {} bytes for a chunk of {} points ({} expected)", rank, bytes,
                                        count, want),
                            "mpi");
            std::memcpy(words_.data() + std::size_t(first) * words_per_point_, data, bytes);
            if (rank != 0)
                stats_.bytes_gathered += bytes;
            stats_.points_per_rank[std::size_t(rank)] += count;
            arrived_[t] = 1;
        };
        queue_ = std::make_unique<Queue>(
            chunks, work, collect, [](std::size_t) { return std::uint64_t(0); }, nullptr);
        if (n == 0)
            end_queue();
    }

    // In order, as the driver asks: waits for the chunks that hold the
    // points, then hands out their words (zeros on ranks other than 0).
    void trace(const TraceChunk& chunk) override {
        const std::size_t w = words_per_point_;
        if (!queue_ && words_.empty()) {
            std::fill(chunk.words.begin(), chunk.words.end(), 0u);
            return;
        }
        if (queue_ && chunk.count > 0) {
            const std::size_t lo = chunk.first / chunk_, hi = (std::size_t(chunk.first) + chunk.count - 1) / chunk_;
            for (std::size_t t = lo; t <= hi; ++t)
                while (!arrived_[t])
                    if (!queue_->pump()) {
                        check_interrupted();
                        nap();
                    }
        }
        std::copy_n(words_.begin() + std::ptrdiff_t(std::size_t(chunk.first) * w), std::size_t(chunk.count) * w,
                    chunk.words.begin());
        if (queue_ && std::size_t(chunk.first) + chunk.count >= n_)
            end_queue();
    }

private:
    std::pair<std::uint32_t, std::uint32_t> range(std::size_t t) const {
        const std::uint32_t first = std::uint32_t(t) * chunk_;
        return {first, std::min(chunk_, n_ - first)};
    }

    std::vector<char> trace_task(std::size_t t) {
        const auto [first, count] = range(t);
        thread_local ChunkInputs inputs;
        std::vector<char> bytes(std::size_t(count) * words_per_point_ * 4);
        const TraceChunk tc = build_(first, count, inputs,
                                     std::span<std::uint32_t>(reinterpret_cast<std::uint32_t*>(bytes.data()),
                                                              std::size_t(count) * words_per_point_));
        local_->trace(tc);
        if (traced_here_++ == 0)
            test_fault_point("chunk");
        return bytes;
    }

    void end_queue() {
        queue_->finish();
        stats_.gather_seconds = queue_->gather_seconds;
        queue_.reset();
        finish_stats();
    }

    void finish_stats() {
        stats_.trace_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        g_stats = stats_;
    }

    std::uint32_t n_ = 0, chunk_ = 1;
    ChunkBuilder build_;
    std::atomic<int> traced_here_{0};
    DistributedStats stats_;
    std::chrono::steady_clock::time_point start_;
    std::vector<std::uint8_t> arrived_;
    std::unique_ptr<Queue> queue_;

private:
    std::unique_ptr<VisibilityTracer> local_;
    std::uint32_t words_per_point_ = 0, local_limit_ = 1;
    std::size_t directions_ = 1;
    std::vector<std::uint32_t> words_; // rank 0: every point's words
};

} // namespace

bool build_has_mpi() {
#if defined(SKYBAKE_HAS_MPI)
    return true;
#else
    return false;
#endif
}

bool launched_by_mpi() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
        if (std::getenv(v))
            return true;
    return false;
}

JobRank join_job() {
#if defined(SKYBAKE_HAS_MPI)
    if (g_joined)
        return g_rank;
    int initialized = 0;
    MPI_Initialized(&initialized);
    if (!initialized) {
        int provided = 0;
        MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
        std::atexit(finalize_at_exit);
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &g_rank.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &g_rank.size);
    MPI_Comm node;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, g_rank.rank, MPI_INFO_NULL, &node);
    MPI_Comm_rank(node, &g_rank.local_rank);
    MPI_Comm_free(&node);
    set_cuda_device_index(g_rank.local_rank); // one rank per GPU on each node
    g_joined = true;
    return g_rank;
#else
    throw Error(kNoMpiMessage, "mpi");
#endif
}

bool joined_job() {
    return g_joined;
}
JobRank job_rank() {
    return g_rank;
}

std::unique_ptr<VisibilityTracer> make_distributed_tracer(std::unique_ptr<VisibilityTracer> local) {
    if (!build_has_mpi())
        throw Error(kNoMpiMessage, "mpi");
    return std::make_unique<DistributedTracer>(std::move(local));
}

DistributedStats last_distributed_stats() {
    return g_stats;
}

std::vector<std::string> run_task_queue(std::size_t count, const std::function<std::string(std::size_t)>& task,
                                        const std::string& label) {
    std::vector<std::string> results(g_rank.rank == 0 ? count : 0);
    const TaskWork work = [&](std::size_t t) {
        const std::string r = task(t);
        return std::vector<char>(r.begin(), r.end());
    };
    const TaskCollect collect = [&](std::size_t t, int, const char* data, std::size_t bytes) {
        results[t].assign(data, bytes);
    };
    double gather = 0.0;
    run_queue(
        count, work, collect, [](std::size_t) { return std::uint64_t(1); }, label, count, gather);
    return results;
}

std::int64_t broadcast_from_root(std::int64_t value) {
#if defined(SKYBAKE_HAS_MPI)
    if (g_joined)
        MPI_Bcast(&value, 1, MPI_INT64_T, 0, MPI_COMM_WORLD);
#endif
    return value;
}

int finish_with_error(const std::string& line, int code) {
#if defined(SKYBAKE_HAS_MPI)
    if (g_joined && g_rank.size > 1) {
        if (g_rank.rank == 0) {
            print_line(line);
            MPI_Abort(MPI_COMM_WORLD, code);
            std::abort();
        }
        std::vector<char> msg(4 + line.size());
        const std::int32_t c = code;
        std::memcpy(msg.data(), &c, 4);
        std::copy(line.begin(), line.end(), msg.begin() + 4);
        MPI_Request request;
        MPI_Isend(msg.data(), int(msg.size()), MPI_BYTE, 0, kTagError, MPI_COMM_WORLD, &request);
        // Rank 0 prints the line and aborts the job, this rank with it; if it
        // is busy for long, this rank reports the error itself.
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(3);
        while (std::chrono::steady_clock::now() < deadline) {
            int flag = 0;
            MPI_Test(&request, &flag, MPI_STATUS_IGNORE);
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        print_line(fmt::format("rank {} of {}: {}", g_rank.rank, g_rank.size, line));
        MPI_Abort(MPI_COMM_WORLD, code);
        std::abort();
    }
#endif
    // Without a job: every process of a launcher that started a build
    // without MPI fails alike; only its rank 0 speaks.
    if (g_joined ? g_rank.rank == 0 : launcher_rank() <= 0)
        print_line(line);
    return code;
}

int finish_with_job_error(const std::string& line, int code) {
    if (g_rank.rank == 0)
        print_line(line);
    return code;
}

void test_fault_point(const char* stage) {
    const char* rank = std::getenv("SKYBAKE_TEST_MPI_FAIL_RANK");
    if (!rank || std::atoi(rank) != g_rank.rank)
        return;
    const std::string at = std::getenv("SKYBAKE_TEST_MPI_FAIL_AT") ? std::getenv("SKYBAKE_TEST_MPI_FAIL_AT") : "chunk";
    if (at == "kill" && std::string(stage) == "chunk")
        std::raise(SIGKILL); // as a crash or the OOM killer would end it
    if (at != stage)
        return;
    throw Error(fmt::format("test failure at '{}' on rank {} (SKYBAKE_TEST_MPI_FAIL_RANK)", stage, g_rank.rank), "mpi");
}

} // namespace skybake
