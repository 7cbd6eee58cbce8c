// The sub-command registry.
//
// Each sub-command file defines `void add_<group>_<name>(CLI::App& group)` and
// registers it at the bottom of the file:
//
//     SKYBAKE_CLI_COMMAND("mesh", add_mesh_info)
//
// Groups are created on first use, in the order of the table in commands.cpp;
// sub-commands within a group are sorted by name, so --help is deterministic.
//
// A group that is itself the command (`skybake ao INPUT ...`) registers with
//
//     SKYBAKE_CLI_GROUP_COMMAND("ao", add_ao_bake)
//
// and its function configures the group's App directly (options, callback);
// such a group takes no sub-commands.
#pragma once

#include <CLI/CLI.hpp>

namespace skybake::cli {

using AddCommandFn = void (*)(CLI::App& group);

struct CommandRegistration {
    CommandRegistration(const char* group, const char* key, AddCommandFn add, bool group_command = false);
};

// Adds every registered group and sub-command to the app.
void add_all_commands(CLI::App& app);

} // namespace skybake::cli

#define SKYBAKE_CLI_COMMAND(group, fn)                                                                                 \
    static const ::skybake::cli::CommandRegistration fn##_registration(group, #fn, fn);

#define SKYBAKE_CLI_GROUP_COMMAND(group, fn)                                                                           \
    static const ::skybake::cli::CommandRegistration fn##_registration(group, #fn, fn, true);
