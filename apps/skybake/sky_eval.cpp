// skybake sky eval: the sky function I(cos α0, cos β0, cos θ0, ρ0) over a CSV file.
#include <charconv>
#include <chrono>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "flags.h"
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

std::vector<std::string> split_fields(const std::string& line) {
    std::vector<std::string> fields;
    std::size_t start = 0;
    for (;;) {
        const std::size_t comma = line.find(',', start);
        fields.push_back(trim(std::string_view(line).substr(start, comma - start)));
        if (comma == std::string::npos)
            break;
        start = comma + 1;
    }
    return fields;
}

constexpr const char* kColumns[4] = {"cos_view_zenith", "cos_view_sun", "cos_sun_zenith", "density"};

// The CSV text of a file, or of standard input for "-".
std::string read_input(const std::string& path) {
    if (path != "-")
        return read_file(path);
    std::ostringstream s;
    s << std::cin.rdbuf();
    return s.str();
}

// Rows of the four columns of kColumns. The first line is a header naming
// them, in any order (other names are an error), or the first row of numbers,
// read in kColumns' order. Blank lines are skipped; no rows is an error.
std::vector<SkySample> read_samples(const std::string& path) {
    const std::string name = path == "-" ? std::string("standard input") : path;
    const std::string text = read_input(path);
    std::vector<SkySample> out;
    std::istringstream in(text);
    std::string line;
    int number = 0;
    bool first_content = true;
    int column[4] = {0, 1, 2, 3}; // field index of each of kColumns
    while (std::getline(in, line)) {
        ++number;
        const std::string where = fmt::format("line {} of {}", number, name);
        if (trim(line).empty())
            continue;
        const std::vector<std::string> fields = split_fields(line);
        double dummy;
        if (first_content && !parse_number(fields[0], dummy)) { // a header: columns by name
            first_content = false;
            for (int& c : column)
                c = -1;
            for (std::size_t i = 0; i < fields.size(); ++i) {
                int k = 0;
                while (k < 4 && fields[i] != kColumns[k])
                    ++k;
                if (k == 4)
                    throw Error(fmt::format("unknown column '{}'; the columns are cos_view_zenith, cos_view_sun, "
                                            "cos_sun_zenith and density, in any order",
                                            fields[i]),
                                where);
                if (column[k] >= 0)
                    throw Error(fmt::format("column '{}' appears twice", fields[i]), where);
                column[k] = int(i);
            }
            for (int k = 0; k < 4; ++k)
                if (column[k] < 0)
                    throw Error(fmt::format("the header has no column '{}'", kColumns[k]), where);
            continue;
        }
        first_content = false;
        if (fields.size() != 4)
            throw Error(fmt::format("expected 4 comma-separated numbers, got {} fields", fields.size()), where);
        double v[4];
        for (int k = 0; k < 4; ++k)
            if (!parse_number(fields[std::size_t(column[k])], v[k]))
                throw Error(fmt::format("{} '{}' is not a number", kColumns[k], fields[std::size_t(column[k])]),
                            where);
        const SkySample s{float(v[0]), float(v[1]), float(v[2]), float(v[3])};
        check_sky_sample(s, where);
        if (!(v[3] > 0.0 && v[3] <= 1.0))
            throw Error(fmt::format("density {} is outside (0, 1]", v[3]), where);
        out.push_back(s);
    }
    if (out.empty())
        throw Error("no samples: the file has no rows of numbers", name);
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
        if (device == Device::Cuda) {
            if (method == SkyMethod::Exact)
                throw UsageError("the exact method runs on the CPU only; use --device cpu or --method tables",
                                 "--device cuda");
            require_cuda_device("--device cuda");
        }
        if (method == SkyMethod::Exact)
            for (const char* f : {"--steps", "--uniform-steps", "--shells", "--cosines"})
                refuse_if_given(*sub, f, "to --method exact (it integrates to a tolerance, without tables)");
        const Atmosphere atm = neural ? net.atmosphere : o->atm.load(*sub);
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
