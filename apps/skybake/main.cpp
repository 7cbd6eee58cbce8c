// skybake: the command-line tool.
//
// Exit codes: 0 success; 1 runtime or input error; 2 usage error.
// Errors are one line on stderr:  skybake: error: <what went wrong> (<where>)
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli.h"
#include "commands.h"
#include "skybake/core.h"
#include "skybake/error.h"

namespace {

std::string version_line() {
    std::string cuda = "without CUDA";
    if (skybake::build_has_cuda()) {
        const int n = skybake::cuda_device_count();
        cuda = n > 0 ? fmt::format("with CUDA, {} device(s): {}", n, skybake::cuda_device_name())
                     : "with CUDA, no device found";
    }
    return fmt::format("skybake {} ({})", skybake::version(), cuda);
}

void print_error(const std::string& line) { std::fprintf(stderr, "skybake: error: %s\n", line.c_str()); }

} // namespace

int main(int argc, char** argv) {
    CLI::App app{"skybake: precomputed lighting for real-time graphics (neural skies, baked visibility)", "skybake"};
    app.require_subcommand(1);
    app.fallthrough(); // inherited by sub-commands: -q and --threads work after them too
    app.set_version_flag("--version", version_line(), "Print the version and whether the build has CUDA");
    bool quiet = false;
    int threads = 0;
    app.add_flag("-q,--quiet", quiet, "No progress bars or informational messages on stderr");
    app.add_option("--threads", threads, "Worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
    app.parse_complete_callback([&] {
        skybake::set_quiet(quiet);
        skybake::set_thread_count(threads);
    });
    skybake::cli::add_all_commands(app);

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        print_error(skybake::format_error_line(e.what(), "command line; see --help"));
        return 2;
    } catch (const skybake::Error& e) {
        print_error(e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        print_error("out of memory");
        return 1;
    } catch (const std::exception& e) {
        print_error(skybake::format_error_line(fmt::format("internal error: {}", e.what()), ""));
        return 1;
    }
    return 0;
}
