// skybake sphere show RULE [--limit N] [--json]
#include <algorithm>

#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "skybake/sphere.h"

namespace skybake::cli {

namespace {

struct ShowOptions {
    std::string rule;
    int limit = -1; // -1: 20 rows on a terminal listing, all in JSON
    bool json = false;
};

void run(const ShowOptions& o) {
    const SphereRule r = parse_flag("rule", [&] { return parse_rule(o.rule); });
    double sum = 0.0, lo = 1e300, hi = -1e300;
    for (double w : r.weights) {
        sum += w;
        lo = std::min(lo, w);
        hi = std::max(hi, w);
    }
    const std::size_t rows = o.limit < 0 ? (o.json ? r.size() : std::min<std::size_t>(20, r.size()))
                                         : std::min<std::size_t>(std::size_t(o.limit), r.size());
    if (o.json) {
        nlohmann::json nodes = nlohmann::json::array();
        for (std::size_t k = 0; k < rows; ++k)
            nodes.push_back({r.points[k].x, r.points[k].y, r.points[k].z, r.weights[k]});
        print_json({{"spec", r.spec},
                    {"kind", rule_kind_name(r.kind)},
                    {"points", r.size()},
                    {"precision", r.precision},
                    {"weight_sum", sum},
                    {"min_weight", lo},
                    {"max_weight", hi},
                    {"negative_weights", r.has_negative_weights()},
                    {"rotate_per_vertex", r.rotate_per_vertex},
                    {"rotation_seed", r.rotation_seed},
                    {"measure", r.kind == RuleKind::Phong ? "2(a+1) max(z,0)^a dw/4pi" : "dw/4pi"},
                    {"nodes", nodes}});
        return;
    }
    fmt::print("rule        {}\n", r.spec);
    fmt::print("kind        {}\n", rule_kind_name(r.kind));
    fmt::print("points      {}\n", r.size());
    fmt::print("precision   {}\n", r.precision < 0 ? std::string("none (not exact for any degree)")
                                                     : fmt::format("{} (exact for polynomials of degree <= {})",
                                                                   r.precision, r.precision));
    fmt::print("weights     sum {:.15f}, min {:.6g}, max {:.6g}{}\n", sum, lo, hi,
               r.has_negative_weights() ? " (some negative: clamp visibility sums to [0, 1])" : "");
    fmt::print("measure     {}\n", r.kind == RuleKind::Phong ? "normalised Phong lobe 2(a+1) max(z,0)^a dw/4pi"
                                                              : "normalised solid angle dw/4pi");
    fmt::print("rotation    {}\n", r.rotate_per_vertex ? fmt::format("random per vertex, seed {}", r.rotation_seed)
                                                       : std::string("none"));
    if (rows == 0)
        return;
    fmt::print("\n{:>6}  {:>22}  {:>22}  {:>22}  {:>22}\n", "#", "x", "y", "z", "w");
    for (std::size_t k = 0; k < rows; ++k)
        fmt::print("{:>6}  {:>22.17g}  {:>22.17g}  {:>22.17g}  {:>22.17g}\n", k, r.points[k].x, r.points[k].y,
                   r.points[k].z, r.weights[k]);
    if (rows < r.size())
        fmt::print("({} of {} points shown; --limit N shows more, 'skybake sphere export' writes them all)\n", rows,
                   r.size());
}

} // namespace

void add_sphere_show(CLI::App& group) {
    auto o = std::make_shared<ShowOptions>();
    CLI::App* sub = group.add_subcommand("show", "Print a rule's points, weights and precision");
    sub->add_option("rule", o->rule, "Rule spec, e.g. lebedev:5810, design:t21, phong:a=32,n=8 (see 'sphere list')")
        ->required();
    sub->add_option("--limit", o->limit, "Rows of points to print (default: 20, all with --json)")
        ->check(integer_in(0, 100'000'000));
    add_json_flag(*sub, o->json);
    sub->callback([o] { run(*o); });
}

SKYBAKE_CLI_COMMAND("sphere", add_sphere_show)

} // namespace skybake::cli
