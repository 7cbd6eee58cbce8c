// skybake sphere list [--json]
#include <filesystem>

#include "cli.h"
#include "commands.h"
#include "skybake/sphere.h"

namespace skybake::cli {

namespace {

struct Family {
    const char* spec;
    const char* description;
};

const Family kFamilies[] = {
    {"mc:N[,seed=S]", "Monte Carlo: N Marsaglia (1972) points, equal weights"},
    {"fibonacci:N", "spherical Fibonacci lattice of N points, equal weights"},
    {"lebedev:N, lebedev:pP", "Lebedev-Laikov rule with N points or precision P (table below)"},
    {"design:tT", "spherical T-design (1 <= T <= 40), equal weights, computed once and cached"},
    {"phong:a=A,n=N", "Phong lobe max(cos,0)^A (DPRT): 2N^2 points, precision 2N-1"},
    {"horizon:NxM", "split at the horizon y=0 (skies): 2NM points, precision min(2N-1, M-1)"},
    {"<rule>+rotate[=SEED]", "the same rule, turned by a random rotation at every vertex"},
};

std::vector<int> cached_designs() {
    std::vector<int> ts;
    if (design_cache_dir().empty()) // the cache is off
        return ts;
    for (int t = 1; t <= 40; ++t) {
        std::error_code ec;
        if (std::filesystem::exists(design_cache_dir() / ("design-v1-t" + std::to_string(t) + ".txt"), ec))
            ts.push_back(t);
    }
    return ts;
}

void run(bool json) {
    const std::vector<int> cached = cached_designs();
    if (json) {
        nlohmann::json families = nlohmann::json::array(), lebedev = nlohmann::json::array();
        for (const Family& f : kFamilies)
            families.push_back({{"spec", f.spec}, {"description", f.description}});
        for (const LebedevInfo& r : lebedev_rules())
            lebedev.push_back({{"precision", r.precision},
                               {"points", r.points},
                               {"spec", fmt::format("lebedev:{}", r.points)},
                               {"negative_weights", r.points == 74 || r.points == 230 || r.points == 266}});
        print_json({{"families", families},
                    {"lebedev", lebedev},
                    {"design_cache_dir", design_cache_dir().string()},
                    {"cached_designs", cached}});
        return;
    }
    fmt::print("Rule specs (for 'sphere show', 'sphere export' and every --rule flag):\n");
    for (const Family& f : kFamilies)
        fmt::print("  {:<24}{}\n", f.spec, f.description);
    fmt::print("\nLebedev-Laikov rules (weights sum to 1; * = some weights negative):\n");
    fmt::print("  {:>9}  {:>6}  {}\n", "precision", "points", "spec");
    for (const LebedevInfo& r : lebedev_rules()) {
        const bool negative = r.points == 74 || r.points == 230 || r.points == 266;
        fmt::print("  {:>9}  {:>6}  lebedev:{}{}\n", r.precision, r.points, r.points, negative ? " *" : "");
    }
    std::string list;
    for (int t : cached)
        list += fmt::format("{}{}", list.empty() ? "" : ", ", t);
    const std::string dir = design_cache_dir().empty() ? std::string("off") : design_cache_dir().string();
    fmt::print("\nDesign cache: {} (cached t: {})\n", dir, list.empty() ? "none" : list);
}

} // namespace

void add_sphere_list(CLI::App& group) {
    auto json = std::make_shared<bool>(false);
    CLI::App* sub = group.add_subcommand("list", "List the rule families and the 32 Lebedev-Laikov rules");
    add_json_flag(*sub, *json);
    sub->callback([json] { run(*json); });
}

SKYBAKE_CLI_COMMAND("sphere", add_sphere_list)

} // namespace skybake::cli
