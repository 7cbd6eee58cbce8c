// The table of sub-command groups and sub-commands.
#pragma once

#include <CLI/CLI.hpp>

namespace skybake::cli {

// Adds every group (mesh, sky, ...) and its sub-commands to the app.
void add_all_commands(CLI::App& app);

} // namespace skybake::cli
