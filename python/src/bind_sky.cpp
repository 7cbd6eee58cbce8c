// The sky: atmospheres, the reference model and the network, evaluated on
// arrays, rendered to arrays and trained (skybake/sky.h, neural.h,
// sky_source.h).
#include <algorithm>
#include <cstring>

#include "common.h"
#include "skybake/image.h"
#include "skybake/neural.h"
#include "skybake/sky.h"
#include "skybake/sky_source.h"

namespace skybake::python {

namespace {

static_assert(sizeof(SkySample) == 4 * sizeof(float), "SkySample is read in place from (N, 4) float32");

SkyView parse_view(const std::string& text) {
    if (text == "fisheye")
        return SkyView::Fisheye;
    if (text == "panorama")
        return SkyView::Panorama;
    if (text == "camera")
        return SkyView::Camera;
    throw Error("unknown view '" + text + "' (fisheye, panorama, camera)", "view");
}

SkyMethod parse_method(const std::string& text) {
    if (text == "tables")
        return SkyMethod::Tables;
    if (text == "exact")
        return SkyMethod::Exact;
    throw Error("unknown method '" + text + "' (tables, exact)", "method");
}

std::span<const SkySample> checked_samples(const py::handle& obj) {
    const auto arr = checked_array<float>(obj, "samples", {-1, 4}, true);
    std::span<const SkySample> samples(reinterpret_cast<const SkySample*>(arr.data()), std::size_t(arr.shape(0)));
    for (std::size_t i = 0; i < samples.size(); ++i)
        check_sky_sample(samples[i], "samples row " + std::to_string(i));
    return samples;
}

py::tuple dvec3_tuple(const glm::dvec3& v) {
    return py::make_tuple(v.x, v.y, v.z);
}

glm::dvec3 dvec3_from(const std::vector<double>& v, const char* name) {
    if (v.size() != 3)
        throw Error("expected 3 values, got " + std::to_string(v.size()), name);
    return {v[0], v[1], v[2]};
}

} // namespace

void bind_sky(py::module_& m) {
    py::class_<Atmosphere>(m, "Atmosphere",
                           "An atmosphere (lengths in km, coefficients per km). Build one with atmosphere_preset(), "
                           "Atmosphere.from_json() or load_atmosphere().")
        .def_readwrite("name", &Atmosphere::name)
        .def_readwrite("planet_radius_km", &Atmosphere::planet_radius_km)
        .def_readwrite("top_radius_km", &Atmosphere::top_radius_km)
        .def_property(
            "ground_albedo", [](const Atmosphere& a) { return dvec3_tuple(a.ground_albedo); },
            [](Atmosphere& a, const std::vector<double>& v) { a.ground_albedo = dvec3_from(v, "ground_albedo"); })
        .def_property(
            "sun_irradiance", [](const Atmosphere& a) { return dvec3_tuple(a.sun_irradiance); },
            [](Atmosphere& a, const std::vector<double>& v) { a.sun_irradiance = dvec3_from(v, "sun_irradiance"); })
        .def_property_readonly("components",
                               [](const Atmosphere& a) {
                                   std::vector<std::string> names;
                                   for (const auto& c : a.components)
                                       names.push_back(c.name);
                                   return names;
                               })
        .def("validate", &Atmosphere::validate, "Raises skybake.Error naming the first bad field.")
        .def("to_json", &atmosphere_to_json)
        .def_static(
            "from_json", [](const std::string& text) { return atmosphere_from_json(text); }, py::arg("text"))
        .def("density_from_altitude", &Atmosphere::density_from_altitude, py::arg("altitude_km"))
        .def("altitude_from_density", &Atmosphere::altitude_from_density, py::arg("density"))
        .def("__repr__", [](const Atmosphere& a) { return "Atmosphere('" + a.name + "')"; });
    m.def(
        "atmosphere_preset",
        [](const std::string& name, double r, double mie) { return atmosphere_preset(name, r, mie); },
        py::arg("name"), py::arg("paper_r") = 10000.0, py::arg("paper_m") = 10000.0,
        "'earth', 'paper' (the seed's r = m = 10000, or paper_r, paper_m) or 'paper-dense'.");
    m.def("atmosphere_presets", &atmosphere_preset_names, "The names atmosphere_preset() takes.");
    m.def("load_atmosphere", &load_atmosphere, py::arg("path"),
          "Reads an atmosphere JSON file; raises skybake.Error naming the bad field.");
    m.def("save_atmosphere", &save_atmosphere, py::arg("path"), py::arg("atmosphere"),
          "Writes an atmosphere JSON file. Atomic.");

    py::class_<NeuralSky>(m, "NeuralSky", "A trained sky network: its topology, weights and atmosphere.")
        .def_property_readonly("topology", [](const NeuralSky& n) { return n.topology.name(); })
        .def_property_readonly("weight_count", [](const NeuralSky& n) { return n.topology.weight_count(); })
        .def_property_readonly(
            "inputs", [](const NeuralSky& n) { return std::string(input_encoding_name(n.encoding.inputs)); },
            "Input encoding: 'seed' or 'horizon'.")
        .def_property_readonly(
            "outputs", [](const NeuralSky& n) { return std::string(output_encoding_name(n.encoding.outputs)); },
            "Output encoding: 'radiance', 'phase-factored' or 'residual'.")
        .def_property_readonly(
            "weights",
            [](const NeuralSky& n) {
                std::vector<float> w = n.weights;
                return to_numpy(std::move(w), {py::ssize_t(n.weights.size())});
            },
            "(W,) float32, a copy, in the layout of skybake/neural.h.")
        .def_readonly("atmosphere", &NeuralSky::atmosphere)
        .def_property_readonly(
            "aerosol_range",
            [](const NeuralSky& n) -> py::object {
                if (!n.encoding.has_family())
                    return py::none();
                return py::make_tuple(n.encoding.aerosol_min, n.encoding.aerosol_max);
            },
            "(min, max) of an aerosol family's amount (train_sky(aerosol_range=...)), else None.")
        .def_property(
            "aerosol", [](const NeuralSky& n) { return n.aerosol; },
            [](NeuralSky& n, double a) {
                NeuralSky t = n;
                t.aerosol = a;
                t.validate("neural sky");
                n.aerosol = a;
            },
            "The aerosol amount of a family network, a multiple of its atmosphere's, within aerosol_range; "
            "1 for others. Every evaluator (Sky.network, export's uniform data) follows it.")
        .def_property_readonly("training",
                               [](const NeuralSky& n) {
                                   py::dict d;
                                   d["samples"] = n.training.samples;
                                   d["seed"] = n.training.seed;
                                   d["adam_epochs"] = n.training.adam_epochs;
                                   d["lm_iterations"] = n.training.lm_iterations;
                                   d["seconds"] = n.training.seconds;
                                   d["train_rms"] = n.training.train_rms;
                                   d["heldout_rms"] = n.training.heldout_rms;
                                   d["heldout_mean_relative"] = n.training.heldout_mean_relative;
                                   return d;
                               })
        .def("to_json", &neural_sky_to_json)
        .def_static(
            "from_json", [](const std::string& text) { return neural_sky_from_json(text); }, py::arg("text"))
        .def(
            "save", [](const NeuralSky& n, const std::filesystem::path& path) { save_neural_sky(path, n); },
            py::arg("path"), "Writes the weights file (JSON). Atomic.")
        .def(
            "export",
            [](const NeuralSky& n, const std::string& language, const std::string& function_name) {
                return export_neural_sky(n, parse_export_language(language, "language"), function_name);
            },
            py::arg("language") = "glsl", py::arg("function_name") = "skybake_sky",
            "Source of the network as a function: 'glsl', 'glsl-es' (GLSL ES 3.00, WebGL 2), 'hlsl', 'cuda' or 'c'.")
        .def("__repr__", [](const NeuralSky& n) {
            return "NeuralSky(topology='" + n.topology.name() + "', weights=" + std::to_string(n.weights.size()) + ")";
        });
    m.def("load_neural_sky", &load_neural_sky, py::arg("path"),
          "Reads a weights file; raises skybake.Error for a missing or corrupt one.");

    py::class_<SkySource>(m, "Sky",
                          "What computes the sky, and where: the reference model or a network, on the CPU or CUDA. "
                          "Radiance is per unit sun irradiance (1/sr).")
        .def_static(
            "reference",
            [](const Atmosphere& atmosphere, const std::string& method, const std::string& device) {
                const SkyMethod sky_method = parse_method(method);
                const Device d = parse_device(device);
                // The tables (seconds with multiple scattering): Ctrl-C stops them.
                return long_call(py::none(), [&] { return SkySource::reference(SkyModel(atmosphere), sky_method, d); });
            },
            py::arg("atmosphere"), py::arg("method") = "tables", py::arg("device") = "cpu",
            "The reference model: 'tables' (the seed's sum) or 'exact' (quadrature; CPU only). The GIL is "
            "released while the tables are built; Ctrl-C stops them.")
        .def_static(
            "network",
            [](const NeuralSky& net, const std::string& device) {
                return SkySource::network(net, parse_device(device));
            },
            py::arg("network"), py::arg("device") = "cpu")
        .def_property_readonly("method", [](const SkySource& s) { return std::string(s.method_name()); })
        .def_property_readonly("device", [](const SkySource& s) { return std::string(device_name(s.device())); })
        .def_property_readonly("is_network", &SkySource::is_network)
        .def_property_readonly("atmosphere", [](const SkySource& s) { return s.atmosphere(); })
        .def(
            "evaluate",
            [](const SkySource& sky, const py::handle& samples) {
                const auto in = checked_samples(samples);
                std::vector<glm::vec3> out(in.size());
                {
                    py::gil_scoped_release release;
                    sky.evaluate(in, out);
                }
                return to_numpy(std::move(out));
            },
            py::arg("samples"),
            "Radiance (N, 3) float32 of samples (N, 4) float32: cos_view_zenith, cos_view_sun, cos_sun_zenith, "
            "density (read in place). Raises skybake.Error for an invalid row.")
        .def(
            "render",
            [](const SkySource& sky, int width, int height, const std::string& view, double altitude_km,
               double sun_elevation_deg, double sun_azimuth_deg, double fov_deg, double yaw_deg, double pitch_deg,
               bool sun_disc, py::object progress) {
                SkyRenderSettings s;
                s.width = width;
                s.height = height;
                s.view = parse_view(view);
                s.altitude_km = altitude_km;
                s.sun_elevation_deg = sun_elevation_deg;
                s.sun_azimuth_deg = sun_azimuth_deg;
                s.fov_deg = fov_deg;
                s.yaw_deg = yaw_deg;
                s.pitch_deg = pitch_deg;
                s.sun_disc = sun_disc;
                s.method = sky.is_network() ? SkyMethod::Tables
                                            : (std::string(sky.method_name()) == "exact" ? SkyMethod::Exact
                                                                                        : SkyMethod::Tables);
                if (width < 1 || height < 1 || width > 16384 || height > 16384)
                    throw Error("width and height must be in 1..16384", "width");
                Image img = long_call(std::move(progress), [&] { return sky.render(s); });
                return image_to_numpy(std::move(img));
            },
            py::arg("width") = 512, py::arg("height") = 512, py::arg("view") = "fisheye",
            py::arg("altitude_km") = 0.0, py::arg("sun_elevation_deg") = 30.0, py::arg("sun_azimuth_deg") = 0.0,
            py::arg("fov_deg") = 90.0, py::arg("yaw_deg") = 0.0, py::arg("pitch_deg") = 0.0,
            py::arg("sun_disc") = true, py::arg("progress") = py::none(),
            "Linear radiance (H, W, 3) float32 times the sun irradiance: view 'fisheye' (the upper hemisphere), "
            "'panorama' (equirectangular, 2:1 for an environment map) or 'camera'.")
        .def("__repr__", [](const SkySource& s) {
            return std::string("Sky(method='") + s.method_name() + "', device='" + device_name(s.device()) + "')";
        });

    m.def(
        "draw_sky_samples",
        [](std::size_t count, std::uint64_t seed) {
            std::vector<SkySample> s = draw_sky_samples(count, seed);
            std::vector<float> flat(s.size() * 4);
            std::memcpy(flat.data(), s.data(), flat.size() * sizeof(float));
            return to_numpy(std::move(flat), {py::ssize_t(s.size()), 4});
        },
        py::arg("count"), py::arg("seed") = 1,
        "`count` valid samples (N, 4) float32, uniform over the sky function's domain. Deterministic.");

    m.def(
        "train_sky",
        [](Atmosphere atmosphere, const std::string& topology, const std::string& inputs,
           std::optional<std::string> outputs, std::size_t samples, std::optional<int> adam_epochs,
           std::optional<int> lm_iterations,
           std::uint64_t seed, const std::string& brightness, const std::string& table_rule, int steps,
           const std::string& device, std::optional<std::pair<double, double>> aerosol_range, double hard_share,
           std::optional<double> flight_share, const std::string& multiple_term, py::object progress) {
            atmosphere.table_rule = parse_table_rule(table_rule, "table_rule");
            atmosphere.validate();
            if (steps < 1 || steps > 4096)
                throw Error("must be in 1..4096", "steps");
            NeuralTrainOptions o;
            o.topology = parse_topology(topology, "topology");
            o.samples = samples;
            o.heldout_samples = std::max<std::size_t>(1000, std::min<std::size_t>(20000, samples / 10));
            const NeuralSchedule schedule = training_schedule(o.topology); // for what is not asked for
            o.adam_epochs = adam_epochs.value_or(schedule.adam_epochs);
            o.lm_iterations = lm_iterations.value_or(schedule.lm_iterations);
            o.learning_rate = schedule.learning_rate;
            o.seed = seed;
            o.brightness = parse_brightness_encoding(brightness, "brightness");
            o.inputs = parse_input_encoding(inputs, "inputs");
            // As `sky train`: default_output_encoding (residual for single scattering).
            o.outputs = outputs ? parse_output_encoding(*outputs, "outputs") : default_output_encoding(atmosphere);
            o.device = parse_device(device);
            o.hard_share = hard_share;
            if (flight_share) {
                if (!(*flight_share >= 0.0 && *flight_share <= 1.0))
                    throw Error("must be in [0, 1]", "flight_share");
                o.flight_share = *flight_share;
            }
            if (multiple_term != "march" && multiple_term != "log")
                throw Error("must be 'march' or 'log'", "multiple_term");
            o.multiple_march = multiple_term == "march";
            if (aerosol_range) {
                o.family_component = "mie";
                o.aerosol_min = aerosol_range->first;
                o.aerosol_max = aerosol_range->second;
            }
            o.progress = true; // events go to the call's callback, never to a bar
            if (samples < 1000)
                throw Error("at least 1000 training samples, got " + std::to_string(samples), "samples");
            if (o.adam_epochs < 0 || o.lm_iterations < 0)
                throw Error("epochs and iterations must be ≥ 0", "adam_epochs");
            SkyModelOptions targets;
            targets.steps = steps;
            targets.tables = kTrainingTargetTables;
            return long_call(std::move(progress), [&] {
                const SkyModel model(atmosphere, targets);
                return train_neural_sky(model, o);
            });
        },
        py::arg("atmosphere"), py::arg("topology") = kDefaultTopology, py::arg("inputs") = "horizon",
        py::arg("outputs") = py::none(), py::arg("samples") = 800000,
        py::arg("adam_epochs") = py::none(), py::arg("lm_iterations") = py::none(), py::arg("seed") = 1,
        py::arg("brightness") = "log", py::arg("table_rule") = "refined", py::arg("steps") = kTrainingTargetSteps,
        py::arg("device") = "cpu", py::arg("aerosol_range") = py::none(), py::arg("hard_share") = 0.0,
        py::arg("flight_share") = py::none(), py::arg("multiple_term") = "march", py::arg("progress") = py::none(),
        "Trains a network on the table path of `atmosphere` (Adam, then Levenberg–Marquardt), as "
        "`skybake sky train`: by default the best small network (shared:16x12, horizon inputs, residual "
        "outputs, with multiple scattering too), trained on the schedule measured for its size (training_schedule: "
        "adam_epochs and lm_iterations None take it), targets from the refined 512 x 256 tables with 64 "
        "steps. aerosol_range=(min, max): one network for the family of atmospheres whose 'mie' amount is that "
        "multiple of the atmosphere's, chosen at run time (NeuralSky.aerosol). hard_share: the share of training "
        "samples drawn near the horizon, the sun and the terminator (importance sampling; 0 by default). "
        "flight_share: the share drawn as a flight's, altitude uniform to 60 km and the sun down to -20 degrees "
        "(None: 0.4 with multiple scattering, else 0). multiple_term: with multiple scattering, 'march' (a "
        "correction of an isotropic march) or 'log' (log-encoded). The seed's network: topology='paper', inputs='seed', outputs='radiance', brightness='linear' "
        "(and table_rule='as-published', steps=16 for its targets). Deterministic for a seed. "
        "topology: 'paper' (324 weights), 'independent:16x16', 'shared:64x64', ...");
}

} // namespace skybake::python
