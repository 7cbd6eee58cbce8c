// skybake sky export: a trained neural sky as a GLSL, GLSL ES, HLSL, CUDA or C function.
#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "skybake/files.h"
#include "skybake/neural.h"

namespace skybake::cli {

void add_sky_export(CLI::App& group) {
    auto* sub = group.add_subcommand("export", "Write a trained neural sky as a self-contained shader or C function");
    struct Opts {
        std::string model, format, output, name = "skybake_sky";
        bool json = false;
    };
    auto o = std::make_shared<Opts>();
    sub->add_option("model", o->model, "Weights file (JSON from `skybake sky train`)")->required();
    sub->add_option("--format", o->format, "glsl (3.30 and later), glsl-es (GLSL ES 3.00, WebGL 2), hlsl, cuda or c")->required();
    sub->add_option("-o,--output", o->output, "Output source file")->required();
    sub->add_option("--name", o->name, "Function name (letters, digits and _)")->capture_default_str();
    add_json_flag(*sub, o->json);
    sub->callback([o] {
        const ExportLanguage lang = parse_flag("--format", [&] { return parse_export_language(o->format); });
        check_output_path(o->output, {}, "--output");
        const NeuralSky net = load_neural_sky(o->model);
        const std::string code = parse_flag("--name", [&] { return export_neural_sky(net, lang, o->name); });
        write_stream_atomic(o->output, [&](std::ostream& f) { f << code; });
        info("{} ({} weights, atmosphere '{}') -> {} function {}() in {}", net.topology.name(),
             net.topology.weight_count(), net.atmosphere.name, o->format, o->name, o->output);
        if (o->json)
            print_json({{"model", o->model},
                        {"format", o->format},
                        {"function", o->name},
                        {"topology", net.topology.name()},
                        {"weights", net.topology.weight_count()},
                        {"bytes", code.size()},
                        {"output", o->output}});
    });
}

SKYBAKE_CLI_COMMAND("sky", add_sky_export)

} // namespace skybake::cli
