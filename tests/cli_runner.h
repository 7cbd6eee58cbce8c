// Runs the skybake CLI as a subprocess and captures its exit code, stdout and
// stderr. For end-to-end tests.
#pragma once

#include <string>
#include <vector>

namespace skybake::test {

struct CliResult {
    int exit_code = -1; // -1: killed by a signal (a crash) or by the timeout
    int signal = 0;
    std::string out, err;
    // Number of lines in err (a trailing newline does not start a new line).
    int err_lines() const;
};

// args do not include the program name. timeout_s kills a hung process.
CliResult run_cli(const std::vector<std::string>& args, int timeout_s = 120);

// Runs the CLI and sends it `sig` after `after_s` seconds (as a user's Ctrl-C
// or a job scheduler's SIGTERM would). With after_fork, the clock starts when
// the CLI has started a child process (the isolated mesh parser), so that the
// signal lands in the middle of the import however slow the start was.
CliResult run_cli_interrupted(const std::vector<std::string>& args, double after_s, int sig, bool after_fork = false,
                              int timeout_s = 120);

// A fresh empty folder under the build tree's temp area, removed by the OS later.
std::string temp_dir(const std::string& name);

// Blender's executable (/usr/bin or /usr/local/bin), or "" without one.
std::string blender_path();

// The JSON text of a .gltf, or of a .glb's JSON chunk.
std::string gltf_json_text(const std::string& path);

} // namespace skybake::test
