// skybake sky preset NAME: prints an atmosphere preset as JSON.
#include "sky_common.h"
#include "commands.h"
#include "flags.h"

namespace skybake::cli {

void add_sky_preset(CLI::App& group) {
    auto* sub = group.add_subcommand("preset", "Print an atmosphere preset as JSON (earth, paper, paper-dense)");
    auto name = std::make_shared<std::string>();
    auto r = std::make_shared<double>(10000.0);
    auto m = std::make_shared<double>(10000.0);
    auto out = std::make_shared<std::string>();
    auto json = std::make_shared<bool>(false);
    sub->add_option("name", *name, "Preset name")->required();
    sub->add_option("--paper-r", *r, "Seed's Rayleigh divisor r, for 'paper' only")
        ->check(real_in(0.0, 1e12, "", End::Open))
        ->capture_default_str();
    sub->add_option("--paper-m", *m, "Seed's Mie divisor m, for 'paper' only")
        ->check(real_in(0.0, 1e12, "", End::Open))
        ->capture_default_str();
    sub->add_option("-o,--output", *out, "Write the JSON to this file instead of stdout");
    add_json_flag(*sub, *json); // the output is JSON either way
    sub->callback([=] {
        if (*name != "paper")
            for (const char* f : {"--paper-r", "--paper-m"})
                refuse_if_given(*sub, f, "to preset " + *name + " (only to paper)");
        if (!out->empty())
            check_output_path(*out, {".json"}, "--output");
        const Atmosphere a = parse_flag("name", [&] { return atmosphere_preset(*name, *r, *m); });
        if (!out->empty()) {
            save_atmosphere(*out, a);
            info("wrote {}", *out);
            if (*json)
                print_json({{"preset", *name}, {"output", *out}});
            return;
        }
        std::fputs(atmosphere_to_json(a).c_str(), stdout);
    });
}

SKYBAKE_CLI_COMMAND("sky", add_sky_preset)

} // namespace skybake::cli
