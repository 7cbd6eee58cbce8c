// skybake: the command-line tool.
//
// Exit codes: 0 success; 1 runtime or input error; 2 usage error (a bad flag
// or flag value); 128 + N when stopped by signal N (SIGINT, SIGTERM).
// Errors are one line on stderr:  skybake: error: <what went wrong> (<where>)
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "skybake/core.h"
#include "skybake/distributed.h"
#include "skybake/error.h"
#include "skybake/interrupt.h"

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

// Prints the one error line and returns the exit code; in an MPI job, ends
// every rank (skybake/distributed.h).
int fail(const std::string& line, int code) { return skybake::finish_with_error(line, code); }

// The command chain as far as it is known ("skybake sky"), for the usage hint.
std::string command_path(const CLI::App* app) {
    std::string s;
    for (; app; app = app->get_parent())
        s = app->get_name() + (s.empty() ? "" : " " + s);
    return s;
}

// After "A subcommand is required": the first word that names no command of
// the level it is given at, if any, as a clearer message than CLI11's.
std::string unknown_command(CLI::App& app, int argc, char** argv) {
    CLI::App* level = &app;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a.rfind("-", 0) == 0) {
            const CLI::Option* o = level->get_option_no_throw(a.substr(0, a.find('=')));
            if (o && o->get_type_size() > 0 && a.find('=') == std::string::npos)
                ++i; // the option's value
            continue;
        }
        CLI::App* next = nullptr;
        for (CLI::App* c : level->get_subcommands({}))
            if (c->check_name(a))
                next = c;
        if (!next) {
            std::string names;
            for (const CLI::App* c : level->get_subcommands({}))
                names += (names.empty() ? "" : ", ") + c->get_name();
            if (names.empty())
                return {};
            return fmt::format("unknown command '{}' for '{}'; use one of: {}", a, command_path(level), names);
        }
        level = next;
    }
    return {};
}

} // namespace

int main(int argc, char** argv) {
    skybake::install_interrupt_handlers(); // first: long loops stop cleanly, leaving no output
    CLI::App app{"skybake: precomputed lighting for real-time graphics (neural skies, baked visibility)", "skybake"};
    app.require_subcommand(1);
    app.fallthrough(); // inherited by sub-commands: -q and --threads work after them too
    app.set_version_flag("--version", version_line(), "Print the version and whether the build has CUDA");
    bool quiet = false;
    int threads = 0;
    app.add_flag("-q,--quiet", quiet, "No progress bars or informational messages on stderr");
    app.add_option("--threads", threads, "Worker threads (0: all cores)")
        ->check(skybake::cli::integer_in(0, 4096))
        ->capture_default_str();
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
        std::string what = e.what();
        if (what.find("subcommand is required") != std::string::npos) {
            const std::string unknown = unknown_command(app, argc, argv);
            if (!unknown.empty())
                what = unknown;
        }
        return fail(skybake::format_error_line(what, "command line; see --help"), 2);
    } catch (const skybake::cli::UsageError& e) {
        const std::string where = e.where().empty() ? "command line" : e.where();
        return fail(skybake::format_error_line(e.message(), where + "; see --help"), 2);
    } catch (const skybake::JobError& e) {
        return skybake::finish_with_job_error(
            skybake::format_error_line(e.message(), skybake::cli::flag_for_field(e.where())), 1);
    } catch (const skybake::Interrupted& e) {
        return fail(e.what(), 128 + e.signal());
    } catch (const skybake::Error& e) {
        return fail(skybake::format_error_line(e.message(), skybake::cli::flag_for_field(e.where())), 1);
    } catch (const std::bad_alloc&) {
        return fail("out of memory", 1);
    } catch (const std::exception& e) {
        return fail(skybake::format_error_line(fmt::format("internal error: {}", e.what()), ""), 1);
    }
    return 0;
}
