// End-to-end tests of the multiple-scattering table cache through `skybake sky
// eval`: the reported time counts the tables, a second process reads them
// from the cache with the same output, a damaged file is recomputed, and
// processes started at once share the folder. Hillaire's method keeps each
// run near a second.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fcntl.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cli_runner.h"

extern char** environ;

using skybake::test::run_cli;
using skybake::test::temp_dir;

namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& path) {
    std::ifstream f(path, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

// SKYBAKE_CACHE_DIR for the CLI processes this test starts, restored afterwards.
class CacheEnv {
public:
    explicit CacheEnv(const std::string& value) {
        const char* old = std::getenv("SKYBAKE_CACHE_DIR");
        had_ = old != nullptr;
        old_ = old ? old : "";
        ::setenv("SKYBAKE_CACHE_DIR", value.c_str(), 1);
    }
    ~CacheEnv() {
        if (had_)
            ::setenv("SKYBAKE_CACHE_DIR", old_.c_str(), 1);
        else
            ::unsetenv("SKYBAKE_CACHE_DIR");
    }

private:
    bool had_ = false;
    std::string old_;
};

std::vector<fs::path> files_in(const fs::path& dir) {
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(dir))
        out.push_back(e.path());
    return out;
}

struct EvalCase {
    std::string dir, input;
};

EvalCase make_input(const std::string& name) {
    EvalCase s;
    s.dir = temp_dir(name);
    s.input = s.dir + "/samples.csv";
    std::ofstream(s.input) << "cos_view_zenith,cos_view_sun,cos_sun_zenith,density\n"
                              "0.5,0.5,0.5,1\n0.05,0.9,0.1,0.8\n1,0.2,0.2,0.3\n-0.2,0.1,0.4,1\n";
    return s;
}

std::vector<std::string> eval_args(const EvalCase& s, const std::string& output) {
    return {"sky",   "eval",     "--scattering", "multiple", "--multiple-method", "hillaire", "--input",
            s.input, "--output", output,         "--json"};
}

nlohmann::json eval_json(const EvalCase& s, const std::string& output) {
    const auto r = run_cli(eval_args(s, output));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(r.out);
}

} // namespace

TEST(SkyCacheCli, ReportedTimeCountsTheTables) {
    const EvalCase s = make_input("cache_time");
    const CacheEnv off("off");
    const auto r = run_cli(eval_args(s, s.dir + "/out.csv"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("multiple scattering ["), std::string::npos) << "no bar when stderr is not a terminal";
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_TRUE(j.contains("precompute_seconds")) << r.out;
    ASSERT_TRUE(j.contains("tables_from_cache")) << r.out;
    EXPECT_FALSE(j["tables_from_cache"].get<bool>());
    const double precompute = j["precompute_seconds"].get<double>(), seconds = j["seconds"].get<double>();
    EXPECT_GT(precompute, 0.0);
    EXPECT_GE(seconds, precompute) << "the reported time leaves out the tables";
}

TEST(SkyCacheCli, SecondProcessReadsTheCacheAndWritesTheSameBytes) {
    const EvalCase s = make_input("cache_second");
    const fs::path cache = fs::path(s.dir) / "cache";
    std::string fresh;
    {
        const CacheEnv off("off");
        eval_json(s, s.dir + "/fresh.csv");
        fresh = read(s.dir + "/fresh.csv");
    }
    ASSERT_FALSE(fresh.empty());
    const CacheEnv env(cache.string());
    const auto first = eval_json(s, s.dir + "/first.csv");
    EXPECT_FALSE(first["tables_from_cache"].get<bool>());
    ASSERT_TRUE(fs::is_directory(cache)) << "the cache folder is created";
    const std::vector<fs::path> files = files_in(cache);
    ASSERT_EQ(files.size(), 1u);
    const auto second = eval_json(s, s.dir + "/second.csv");
    EXPECT_TRUE(second["tables_from_cache"].get<bool>());
    EXPECT_EQ(read(s.dir + "/first.csv"), fresh);
    EXPECT_EQ(read(s.dir + "/second.csv"), fresh);

    // A truncated file: recomputed without a word, same output, and whole again.
    const std::string whole = read(files.front());
    fs::resize_file(files.front(), whole.size() / 3);
    const auto r = run_cli(eval_args(s, s.dir + "/third.csv"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("error"), std::string::npos) << r.err;
    EXPECT_FALSE(nlohmann::json::parse(r.out)["tables_from_cache"].get<bool>());
    EXPECT_EQ(read(s.dir + "/third.csv"), fresh);
    EXPECT_EQ(read(files.front()), whole);
    EXPECT_TRUE(eval_json(s, s.dir + "/fourth.csv")["tables_from_cache"].get<bool>());
}

TEST(SkyCacheCli, ProcessesStartedAtOnceShareTheFolder) {
    const EvalCase s = make_input("cache_concurrent");
    const fs::path cache = fs::path(s.dir) / "cache";
    std::string fresh;
    {
        const CacheEnv off("off");
        eval_json(s, s.dir + "/fresh.csv");
        fresh = read(s.dir + "/fresh.csv");
    }
    const CacheEnv env(cache.string());
    constexpr int kProcesses = 3;
    std::vector<pid_t> pids;
    for (int i = 0; i < kProcesses; ++i) {
        std::vector<std::string> args = eval_args(s, s.dir + "/out" + std::to_string(i) + ".csv");
        args.insert(args.begin(), SKYBAKE_CLI_PATH);
        std::vector<char*> argv;
        for (std::string& a : args)
            argv.push_back(a.data());
        argv.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
        posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
        pid_t pid = 0;
        ASSERT_EQ(posix_spawn(&pid, SKYBAKE_CLI_PATH, &actions, nullptr, argv.data(), environ), 0);
        posix_spawn_file_actions_destroy(&actions);
        pids.push_back(pid);
    }
    for (pid_t pid : pids) {
        int status = 0;
        ASSERT_EQ(waitpid(pid, &status, 0), pid);
        EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
    }
    for (int i = 0; i < kProcesses; ++i)
        EXPECT_EQ(read(s.dir + "/out" + std::to_string(i) + ".csv"), fresh) << i;
    const std::vector<fs::path> files = files_in(cache);
    ASSERT_EQ(files.size(), 1u) << "one table file and no temporaries";
    EXPECT_TRUE(eval_json(s, s.dir + "/after.csv")["tables_from_cache"].get<bool>());
    EXPECT_EQ(read(s.dir + "/after.csv"), fresh);
}
