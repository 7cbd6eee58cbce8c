// skybake sky eval: the sky function I(cos α0, cos β0, cos θ0, ρ0) over a CSV file.
#include <charconv>
#include <chrono>
#include <sstream>

#include "commands.h"
#include "skybake/files.h"
#include "sky_common.h"

namespace skybake::cli {

namespace {

std::string trim(std::string_view s) {
    std::size_t a = 0, b = s.size();
    while (a < b && (s[a] == ' ' || s[a] == '\t' || s[a] == '\r'))
        ++a;
    while (b > a && (s[b - 1] == ' ' || s[b - 1] == '\t' || s[b - 1] == '\r'))
        --b;
    return std::string(s.substr(a, b - a));
}

bool parse_number(const std::string& s, double& out) {
    if (s.empty())
        return false;
    const char* first = s.data();
    if (*first == '+')
        ++first;
    const auto r = std::from_chars(first, s.data() + s.size(), out);
    return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

// Rows of "cos_view_zenith,cos_view_sun,cos_sun_zenith,density"; the first
// line may be a header. Blank lines are skipped.
std::vector<SkySample> read_samples(const std::string& path) {
    const std::string text = read_file(path);
    std::vector<SkySample> out;
    std::istringstream in(text);
    std::string line;
    int number = 0;
    bool first_content = true;
    while (std::getline(in, line)) {
        ++number;
        const std::string where = fmt::format("line {} of {}", number, path);
        if (trim(line).empty())
            continue;
        std::vector<std::string> fields;
        std::size_t start = 0;
        for (;;) {
            const std::size_t comma = line.find(',', start);
            fields.push_back(trim(std::string_view(line).substr(start, comma - start)));
            if (comma == std::string::npos)
                break;
            start = comma + 1;
        }
        double v[4];
        bool numeric = fields.size() == 4;
        for (std::size_t i = 0; numeric && i < 4; ++i)
            numeric = parse_number(fields[i], v[i]);
        if (!numeric) {
            double dummy;
            if (first_content && !parse_number(fields[0], dummy)) { // a header
                first_content = false;
                continue;
            }
            if (fields.size() != 4)
                throw Error(fmt::format("expected 4 comma-separated numbers "
                                        "(cos_view_zenith,cos_view_sun,cos_sun_zenith,density), got {} fields",
                                        fields.size()),
                            where);
            throw Error("not a number: every field must be a decimal number", where);
        }
        first_content = false;
        const SkySample s{float(v[0]), float(v[1]), float(v[2]), float(v[3])};
        check_sky_sample(s, where);
        if (!(v[3] > 0.0 && v[3] <= 1.0))
            throw Error(fmt::format("density {} is outside (0, 1]", v[3]), where);
        out.push_back(s);
    }
    return out;
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
    sub->add_option("--method", o->method, "tables (the seed's sum over its tables, default) or exact");
    sub->add_option("--input", o->input, "CSV rows: cos_view_zenith,cos_view_sun,cos_sun_zenith,density")->required();
    sub->add_option("--output", o->output, "CSV rows r,g,b: radiance per unit sun irradiance, 1/sr")->required();
    sub->add_option("--steps", o->steps, "Steps of the sum along each view ray (default 16)");
    sub->add_option("--device", o->device, "cpu (default) or cuda (tables method and networks)");
    sub->add_flag("--uniform-steps", o->uniform, "Use the seed's uniform step length instead of graded steps");
    sub->add_option("--shells", o->shells, "Table rows n (default 256)");
    sub->add_option("--cosines", o->cosines, "Table columns m (default 128)");
    add_json_flag(*sub, o->json);
    sub->callback([o, sub] {
        const bool neural = o->model.active();
        const NeuralSky net = neural ? o->model.load(*sub, o->atm) : NeuralSky{};
        const SkyMethod method = neural ? SkyMethod::Tables : parse_sky_method(o->method);
        const Device device = parse_device(o->device);
        if (device == Device::Cuda) {
            require_cuda_device("--device cuda");
            if (method == SkyMethod::Exact)
                throw Error("the exact method runs on the CPU only; use --device cpu or --method tables",
                            "--device cuda");
        }
        const Atmosphere atm = neural ? net.atmosphere : o->atm.load();
        const std::vector<SkySample> samples = read_samples(o->input);
        SkyModelOptions opts;
        opts.steps = o->steps;
        opts.uniform_steps = o->uniform;
        opts.tables = {o->shells, o->cosines};
        const auto t0 = std::chrono::steady_clock::now();
        std::vector<glm::vec3> out(samples.size());
        if (neural && device == Device::Cuda)
            evaluate_neural_sky_cuda(net, samples, out);
        else if (neural)
            evaluate_neural_sky(net, samples, out);
        else if (device == Device::Cuda)
            evaluate_sky_cuda(SkyModel(atm, opts), samples, out);
        else
            evaluate_sky(SkyModel(atm, opts), samples, out, method);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        write_stream_atomic(o->output, [&](std::ostream& f) {
            f << "r,g,b\n";
            for (const glm::vec3& c : out)
                f << fmt::format("{:.9g},{:.9g},{:.9g}\n", c.x, c.y, c.z);
        });
        const std::string method_name = neural ? "neural" : o->method;
        info("{} samples, {} method on {}, {:.3f} s -> {}", samples.size(), method_name, o->device, seconds, o->output);
        if (o->json)
            print_json({{"atmosphere", atm.name},
                        {"method", method_name},
                        {"device", o->device},
                        {"model", o->model.path},
                        {"samples", samples.size()},
                        {"steps", o->steps},
                        {"seconds", seconds},
                        {"output", o->output}});
    });
}

SKYBAKE_CLI_COMMAND("sky", add_sky_eval)

} // namespace skybake::cli
