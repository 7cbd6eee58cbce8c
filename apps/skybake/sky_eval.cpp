// skybake sky eval: the sky function I(cos α0, cos β0, cos θ0, ρ0) over a CSV file.
#include <chrono>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "flags.h"
#include "skybake/files.h"
#include "skybake/sky_source.h"
#include "sky_common.h"

namespace skybake::cli {

namespace {

// The CSV text of a file, or of standard input for "-".
std::string read_input(const std::string& path) {
    if (path != "-")
        return read_file(path);
    std::ostringstream s;
    s << std::cin.rdbuf();
    return s.str();
}

// Rows of a sky CSV file, or of standard input for "-" (see read_sky_samples_csv).
std::vector<SkySample> read_samples(const std::string& path) {
    return read_sky_samples_csv(read_input(path), path == "-" ? std::string("standard input") : path);
}

} // namespace

void add_sky_eval(CLI::App& group) {
    auto* sub = group.add_subcommand("eval", "Evaluate the sky colour for rows of cosines and densities (CSV)");
    struct Opts {
        AtmosphereFlags atm;
        ModelFlag model;
        std::string method = "tables", input, output, device = "cpu";
        int steps = 16, shells = 256, cosines = 128;
        bool uniform = false, json = false;
    };
    auto o = std::make_shared<Opts>();
    o->atm.add(*sub);
    o->model.add(*sub);
    sub->add_option("--method", o->method, "tables (the seed's sum over its tables) or exact")->capture_default_str();
    sub->add_option("--input", o->input,
                    "CSV with the columns cos_view_zenith,cos_view_sun,cos_sun_zenith,density (a header names them, "
                    "in any order); - for standard input")
        ->required();
    sub->add_option("--output", o->output, "CSV rows r,g,b: radiance per unit sun irradiance, 1/sr; - for standard "
                                           "output")
        ->required();
    sub->add_option("--steps", o->steps, "Steps of the sum along each view ray")
        ->check(integer_in(1, 4096))
        ->capture_default_str();
    sub->add_option("--device", o->device, "cpu or cuda (tables method and networks)")->capture_default_str();
    sub->add_flag("--uniform-steps", o->uniform, "Use the seed's uniform step length instead of graded steps");
    sub->add_option("--shells", o->shells, "Table rows n")->check(integer_in(2, 16384))->capture_default_str();
    sub->add_option("--cosines", o->cosines, "Table columns m")->check(integer_in(2, 16384))->capture_default_str();
    add_json_flag(*sub, o->json);
    sub->callback([o, sub] {
        if (o->json && o->output == "-")
            throw UsageError("--json and --output - both write to standard output; write the CSV to a file",
                             "--json");
        check_output_path(o->output, {".csv"}, "--output");
        const bool neural = o->model.active();
        const NeuralSky net = neural ? o->model.load(*sub, o->atm) : NeuralSky{};
        const SkyMethod method = neural ? SkyMethod::Tables : parse_sky_method(o->method);
        const Device device = parse_flag("--device", [&] { return parse_device(o->device); });
        if (device == Device::Cuda && method == SkyMethod::Exact)
            throw UsageError("the exact method runs on the CPU only; use --device cpu or --method tables",
                             "--device cuda");
        if (method == SkyMethod::Exact)
            for (const char* f : {"--steps", "--uniform-steps", "--shells", "--cosines"})
                refuse_if_given(*sub, f, "to --method exact (it integrates to a tolerance, without tables)");
        const Atmosphere atm = neural ? net.atmosphere : o->atm.load(*sub);
        const std::vector<SkySample> samples = read_samples(o->input);
        SkyModelOptions opts;
        opts.steps = o->steps;
        opts.uniform_steps = o->uniform;
        opts.tables = {o->shells, o->cosines};
        // The reported time counts the tables (the multiple-scattering tables
        // take seconds unless the cache has them) and the evaluation.
        const auto t0 = std::chrono::steady_clock::now();
        // No GPU: a runtime error (exit 1), before any work.
        const SkySource source =
            neural ? SkySource::network(net, device) : SkySource::reference(SkyModel(atm, opts), method, device);
        const SkyModel& tables = source.tables();
        std::vector<glm::vec3> out(samples.size());
        source.evaluate(samples, out);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const auto write_rows = [&](std::ostream& f) {
            f << "r,g,b\n";
            for (const glm::vec3& c : out)
                f << fmt::format("{:.9g},{:.9g},{:.9g}\n", c.x, c.y, c.z);
        };
        if (o->output == "-") {
            write_rows(std::cout);
            std::cout.flush();
        } else {
            write_stream_atomic(o->output, write_rows);
        }
        const std::string method_name = neural ? "neural" : o->method;
        const bool multiple = tables.atmosphere().scattering == Scattering::Multiple;
        const std::string precompute =
            multiple ? fmt::format(" (multiple-scattering tables {:.3f} s, {})", tables.multiple_precompute_seconds(),
                                   tables.multiple_tables_from_cache() ? "from the cache" : "computed")
                     : std::string();
        info("{} samples, {} method on {}, {:.3f} s{} -> {}", samples.size(), method_name, o->device, seconds,
             precompute, o->output);
        if (o->json)
            print_json({{"atmosphere", atm.name},
                        {"method", method_name},
                        {"device", o->device},
                        {"model", o->model.path},
                        {"samples", samples.size()},
                        {"steps", o->steps},
                        {"seconds", seconds},
                        {"precompute_seconds", tables.multiple_precompute_seconds()},
                        {"tables_from_cache", tables.multiple_tables_from_cache()},
                        {"output", o->output}});
    });
}

SKYBAKE_CLI_COMMAND("sky", add_sky_eval)

} // namespace skybake::cli
