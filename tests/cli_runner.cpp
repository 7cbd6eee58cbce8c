#include "cli_runner.h"

#include "skybake/gltf_asset.h"

#include <csignal>
#include <cstdint>
#include <cstring>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

namespace skybake::test {

int CliResult::err_lines() const {
    int n = 0;
    for (char c : err)
        n += c == '\n';
    if (!err.empty() && err.back() != '\n')
        ++n;
    return n;
}

std::string temp_dir(const std::string& name) {
    namespace fs = std::filesystem;
    fs::path p = fs::temp_directory_path() / ("skybake-test-" + std::to_string(::getpid())) / name;
    fs::remove_all(p);
    fs::create_directories(p);
    return p.string();
}

namespace {
// Whether process `pid` has a child process now.
bool has_child(pid_t pid) {
    std::ifstream children("/proc/" + std::to_string(pid) + "/task/" + std::to_string(pid) + "/children");
    std::string first;
    return bool(children >> first);
}

// Whether process `pid` runs the CLI and has installed its handler for `sig`
// (/proc/PID/status, SigCgt). A fixed delay is not enough on a loaded
// machine: a signal sent before the handlers exist kills the process.
bool catches(pid_t pid, int sig) {
    std::error_code ec;
    const auto exe = std::filesystem::read_symlink("/proc/" + std::to_string(pid) + "/exe", ec);
    if (ec || exe != std::filesystem::path(SKYBAKE_CLI_PATH).lexically_normal())
        return false;
    std::ifstream status("/proc/" + std::to_string(pid) + "/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("SigCgt:", 0) == 0)
            return (std::stoull(line.substr(7), nullptr, 16) >> (sig - 1)) & 1u;
    return false;
}

CliResult run(const std::vector<std::string>& args, int timeout_s, double signal_after_s, int sig, bool after_fork) {
    namespace fs = std::filesystem;
    static int counter = 0;
    const fs::path dir = temp_dir("cli-capture");
    const fs::path out_path = dir / ("out" + std::to_string(counter));
    const fs::path err_path = dir / ("err" + std::to_string(counter++));
    CliResult r;
    pid_t pid = fork();
    if (pid == 0) {
        FILE* o = std::freopen(out_path.c_str(), "w", stdout);
        FILE* e = std::freopen(err_path.c_str(), "w", stderr);
        if (!o || !e)
            _exit(127);
        alarm(unsigned(timeout_s)); // SIGALRM kills a hang
        std::vector<char*> argv;
        std::string prog = SKYBAKE_CLI_PATH;
        argv.push_back(prog.data());
        std::vector<std::string> copy = args;
        for (auto& a : copy)
            argv.push_back(a.data());
        argv.push_back(nullptr);
        execv(prog.c_str(), argv.data());
        _exit(127);
    }
    int status = 0;
    if (signal_after_s > 0.0) {
        for (int i = 0; i < 6000 && !catches(pid, sig); ++i)
            usleep(10000); // up to a minute for the CLI to install its handlers
        for (int i = 0; after_fork && i < 6000 && !has_child(pid); ++i)
            usleep(10000); // up to a minute for the CLI to start its parser
        usleep(useconds_t(signal_after_s * 1e6));
        kill(pid, sig);
    }
    waitpid(pid, &status, 0);
    if (WIFEXITED(status))
        r.exit_code = WEXITSTATUS(status);
    else if (WIFSIGNALED(status))
        r.signal = WTERMSIG(status);
    auto slurp = [](const fs::path& p) {
        std::ifstream in(p, std::ios::binary);
        std::stringstream ss;
        ss << in.rdbuf();
        return ss.str();
    };
    r.out = slurp(out_path);
    r.err = slurp(err_path);
    return r;
}
} // namespace

CliResult run_cli(const std::vector<std::string>& args, int timeout_s) {
    return run(args, timeout_s, 0.0, 0, false);
}

CliResult run_cli_interrupted(const std::vector<std::string>& args, double after_s, int sig, bool after_fork,
                              int timeout_s) {
    return run(args, timeout_s, after_s, sig, after_fork);
}

std::string blender_path() {
    for (const char* dir : {"/usr/bin", "/usr/local/bin"}) {
        const std::string p = std::string(dir) + "/blender";
        if (access(p.c_str(), X_OK) == 0)
            return p;
    }
    return {};
}

std::string gltf_json_text(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (path.size() >= 5 && path.compare(path.size() - 5, 5, ".gltf") == 0)
        return data;
    return glb_json_chunk(data, path);
}

} // namespace skybake::test
