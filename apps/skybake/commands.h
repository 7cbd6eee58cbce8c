// The sub-command registry.
//
// Each sub-command file defines `void add_<group>_<name>(CLI::App& group)` and
// registers it at the bottom of the file:
//
//     SKYBAKE_CLI_COMMAND("mesh", add_mesh_info)
//
// Groups are created on first use, in the order of the table in commands.cpp;
// sub-commands within a group are sorted by name, so --help is deterministic.
#pragma once

#include <CLI/CLI.hpp>

namespace skybake::cli {

using AddCommandFn = void (*)(CLI::App& group);

struct CommandRegistration {
    CommandRegistration(const char* group, const char* key, AddCommandFn add);
};

// Adds every registered group and sub-command to the app.
void add_all_commands(CLI::App& app);

} // namespace skybake::cli

#define SKYBAKE_CLI_COMMAND(group, fn)                                                                                 \
    static const ::skybake::cli::CommandRegistration fn##_registration(group, #fn, fn);
