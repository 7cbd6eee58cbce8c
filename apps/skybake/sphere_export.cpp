// skybake sphere export RULE -o points.csv [--json]
#include <ostream>

#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "skybake/files.h"
#include "skybake/sphere.h"

namespace skybake::cli {

namespace {

struct ExportOptions {
    std::string rule;
    std::string output;
    bool json = false;
};

void run(const ExportOptions& o) {
    const SphereRule r = parse_flag("rule", [&] { return parse_rule(o.rule); });
    check_output_path(o.output, {".csv"}, "--output");
    write_stream_atomic(o.output, [&](std::ostream& out) {
        out << "x,y,z,w\n";
        for (std::size_t k = 0; k < r.size(); ++k)
            out << fmt::format("{:.17g},{:.17g},{:.17g},{:.17g}\n", r.points[k].x, r.points[k].y, r.points[k].z,
                               r.weights[k]);
    });
    if (o.json) {
        print_json({{"spec", r.spec}, {"points", r.size()}, {"precision", r.precision}, {"output", o.output}});
        return;
    }
    info("wrote {} points of {} to {}", r.size(), r.spec, o.output);
}

} // namespace

void add_sphere_export(CLI::App& group) {
    auto o = std::make_shared<ExportOptions>();
    CLI::App* sub = group.add_subcommand("export", "Write a rule as CSV rows x,y,z,w (full double precision)");
    sub->add_option("rule", o->rule, "Rule spec, e.g. lebedev:5810 (see 'sphere list')")->required();
    sub->add_option("-o,--output", o->output, "Output CSV file (written atomically)")->required();
    add_json_flag(*sub, o->json);
    sub->callback([o] { run(*o); });
}

SKYBAKE_CLI_COMMAND("sphere", add_sphere_export)

} // namespace skybake::cli
