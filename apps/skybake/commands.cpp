#include "commands.h"

#include <algorithm>
#include <string>
#include <vector>

namespace skybake::cli {

namespace {

struct Entry {
    std::string group, key;
    AddCommandFn add;
    bool group_command = false;
};

std::vector<Entry>& registry() {
    static std::vector<Entry> entries;
    return entries;
}

struct Group {
    const char* name;
    const char* description;
};

// Every group the tool knows, in --help order.
const Group kGroups[] = {
    {"mesh", "Inspect, convert and generate meshes"},
    {"sky", "Atmospheric scattering: reference model, neural sky, rendering and shader export"},
    {"sphere", "Quadrature rules on the sphere and spherical harmonics"},
    {"ao", "Bake per-vertex ambient occlusion and shading coefficients"},
    {"prt", "Bake spherical-harmonic transfer (PRT/DPRT)"},
    {"fly", "Render frames of a flight from sea level to space (OpenGL, headless)"},
    {"view", "Interactive viewers (OpenGL window)"},
    {"web", "Write a static web site of a baked model under the neural sky (WebGL 2)"},
};

} // namespace

CommandRegistration::CommandRegistration(const char* group, const char* key, AddCommandFn add, bool group_command) {
    registry().push_back({group, key, add, group_command});
}

void add_all_commands(CLI::App& app) {
    auto entries = registry();
    std::sort(entries.begin(), entries.end(),
              [](const Entry& a, const Entry& b) { return a.group != b.group ? a.group < b.group : a.key < b.key; });
    for (const Group& g : kGroups) {
        CLI::App* group = nullptr;
        for (const Entry& e : entries) {
            if (e.group != g.name)
                continue;
            if (!group) {
                group = app.add_subcommand(g.name, g.description);
                if (!e.group_command)
                    group->require_subcommand(1);
            }
            e.add(*group);
        }
    }
}

} // namespace skybake::cli
