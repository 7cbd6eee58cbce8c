// skybake prt export [BAKED.glb] [--order L --channels C] [--model W.json --glossy A [--nodes N]]
//                   [--format glsl|glsl-es] -o OUT.glsl
// The GLSL relighting functions (skybake/prt.h, [SECTION] Shader export).
#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "skybake/files.h"
#include "skybake/prt.h"

namespace skybake::cli {

void add_prt_export(CLI::App& group) {
    auto* sub =
        group.add_subcommand("export", "Write the GLSL relighting functions (diffuse PRT, DPRT with a network)");
    struct Opts {
        std::string input, output, model, function = "skybake_prt", convention = "skybake", format = "glsl";
        int order = 3, channels = 1, nodes = 0;
        double glossy = 0.0;
    };
    auto o = std::make_shared<Opts>();
    sub->add_option("input", o->input, "A mesh from 'prt bake': takes its order and channels from the sidecar");
    sub->add_option("-o,--output", o->output, "GLSL file")->required();
    sub->add_option("--order", o->order, "SH order (without an input)")
        ->check(integer_in(0, kPrtMaxOrder))
        ->capture_default_str();
    sub->add_option("--channels", o->channels, "1 (grey transfer) or 3 (interreflected; without an input)")
        ->check(integer_in(1, 3))
        ->capture_default_str();
    sub->add_option("--model", o->model, "Sky network weights: adds NAME_glossy (DPRT with the network)");
    sub->add_option("--glossy", o->glossy, "Phong exponent of the glossy function (with --model)")
        ->check(real_in(0.0, 10000.0, "", End::Open));
    sub->add_option("--nodes", o->nodes, "Nodes in cos θ of the Phong rule (default: order/2 + 1)")
        ->check(integer_in(1, 64));
    sub->add_option("--name", o->function, "Function name prefix (letters, digits and _)")->capture_default_str();
    sub->add_option("--format", o->format, "glsl (3.30 and later) or glsl-es (GLSL ES 3.00, WebGL 2)")
        ->capture_default_str();
    sub->add_option("--sh-convention", o->convention,
                    "Convention of the light[] the diffuse function takes: skybake (as `sky sh` writes by default) "
                    "or condon-shortley ((-1)^m, Sloan 2008 and D3DX: the function negates the odd-|m| terms)")
        ->capture_default_str();
    sub->callback([o, sub] {
        check_output_path(o->output, {".glsl", ".vert", ".frag", ".txt"}, "--output");
        if (!valid_shader_identifier(o->function))
            throw UsageError(fmt::format("'{}' is not a valid function name prefix (letters, digits and _, not "
                                         "starting with a digit or gl_)",
                                         o->function),
                             "--name");
        if (o->model.empty() != (o->glossy == 0.0))
            throw UsageError("--model and --glossy go together", o->model.empty() ? "--glossy" : "--model");
        if (o->model.empty())
            refuse_if_given(*sub, "--nodes", "without --model");
        if (o->channels == 2)
            throw UsageError("a transfer has 1 or 3 channels", "--channels");
        int order = o->order, channels = o->channels;
        if (!o->input.empty()) {
            refuse_if_given(*sub, "--order", "with an input (its sidecar gives it)");
            refuse_if_given(*sub, "--channels", "with an input (its sidecar gives it)");
            const PrtModel m = load_prt(o->input);
            order = m.transfer.order;
            channels = m.transfer.channels;
        }
        if (o->format != "glsl" && o->format != "glsl-es")
            throw UsageError(fmt::format("unknown format '{}'; use glsl or glsl-es", o->format), "--format");
        PrtShaderOptions so;
        so.function_name = o->function;
        so.es = o->format == "glsl-es";
        so.light_convention = parse_flag("--sh-convention", [&] { return parse_sh_convention(o->convention); });
        NeuralSky net;
        SphereRule phong;
        if (!o->model.empty()) {
            net = load_neural_sky(o->model);
            phong = phong_rule(o->glossy, o->nodes > 0 ? o->nodes : order / 2 + 1);
            so.network = &net;
            so.phong = &phong;
        }
        const std::string text = export_prt_glsl(order, channels, so);
        write_stream_atomic(o->output, [&](std::ostream& out) { out << text; });
        info("wrote {} (order {}, {} channel{}{})", o->output, order, channels, channels == 1 ? "" : "s",
             o->model.empty() ? "" : fmt::format(", DPRT over {}", phong.spec));
    });
}

SKYBAKE_CLI_COMMAND("prt", add_prt_export)

} // namespace skybake::cli
