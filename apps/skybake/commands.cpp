#include "commands.h"

#include <initializer_list>

namespace skybake::cli {

// One declaration per sub-command file.
//void add_mesh_info(CLI::App& group);
//void add_mesh_generate(CLI::App& group);
//void add_mesh_convert(CLI::App& group);

namespace {

using AddFn = void (*)(CLI::App&);

void add_group(CLI::App& app, const char* name, const char* description, std::initializer_list<AddFn> subs) {
    CLI::App* group = app.add_subcommand(name, description);
    group->require_subcommand(1);
    for (AddFn add : subs)
        add(*group);
}

} // namespace

void add_all_commands(CLI::App& app) {
    // groups are added here
}

} // namespace skybake::cli
