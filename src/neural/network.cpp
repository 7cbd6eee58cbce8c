// Topologies and the weights file of the neural sky (Pietras & Rudnicki,
// seed 000, section III: four independent 4 -> 8 -> 4 -> 1 sub-networks, 324
// weights, and the general widths/depths built on the same layout).
#include <charconv>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "neural/internal.h"
#include "skybake/error.h"
#include "skybake/names.h"
#include "skybake/files.h"

namespace skybake {

using json = nlohmann::json;

namespace {

constexpr const char* kFormat = "skybake-neural-sky";
// 1: the seed's inputs and radiance outputs. 2: input and output encodings,
// topology.outputs. 3: horizon inputs put the zenith and nadir 2 * kHorizonGap
// apart. Versions 1 and 3 load, and so does version 2 with seed inputs;
// version 2's horizon inputs (no gap) are refused rather than misread.
constexpr int kVersion = 3;

} // namespace

int NeuralTopology::subnet_weight_count() const {
    int in = inputs, n = 0;
    for (int w : hidden) {
        n += (in + 1) * w;
        in = w;
    }
    return n + (in + 1) * outputs_per_subnet();
}

std::string NeuralTopology::name() const {
    if (!shared && outputs == 4 && hidden == std::vector<int>{8, 4})
        return "paper";
    std::string s = shared ? "shared:" : "independent:";
    for (std::size_t i = 0; i < hidden.size(); ++i)
        s += (i ? "x" : "") + std::to_string(hidden[i]);
    return s;
}

void NeuralTopology::validate(const std::string& where) const {
    if (hidden.empty() || int(hidden.size()) > neural::kMaxHidden)
        throw Error(fmt::format("a network needs 1 to {} hidden layers, got {}", neural::kMaxHidden, hidden.size()),
                    where);
    for (int w : hidden)
        if (w < 1 || w > neural::kMaxWidth)
            throw Error(fmt::format("hidden layer width {} is outside 1..{}", w, neural::kMaxWidth), where);
    if (outputs < 1 || outputs > neural::kMaxOutputs)
        throw Error(fmt::format("a network has 1 to {} outputs, not {}", neural::kMaxOutputs, outputs), where);
    if (inputs < neural::kInputs || inputs > neural::kMaxInputs)
        throw Error(fmt::format("a network has {} or {} inputs, not {}", neural::kInputs, neural::kMaxInputs, inputs),
                    where);
}

NeuralTopology parse_topology(std::string_view text, const std::string& where) {
    const std::string usage = "use paper, independent:W1xW2... or shared:W1xW2... (e.g. independent:16x16)";
    NeuralTopology t;
    if (text == "paper")
        return t;
    const std::size_t colon = text.find(':');
    if (colon == std::string_view::npos)
        throw Error(fmt::format("unknown topology '{}'; {}", text, usage), where);
    const std::string_view kind = text.substr(0, colon);
    if (kind == "shared")
        t.shared = true;
    else if (kind != "independent")
        throw Error(fmt::format("unknown topology kind '{}'; {}", kind, usage), where);
    t.hidden.clear();
    std::string_view rest = text.substr(colon + 1);
    for (;;) {
        const std::size_t x = rest.find('x');
        const std::string_view part = rest.substr(0, x);
        int w = 0;
        const auto r = std::from_chars(part.data(), part.data() + part.size(), w);
        if (part.empty() || r.ec != std::errc() || r.ptr != part.data() + part.size())
            throw Error(fmt::format("bad layer width '{}' in topology '{}'; {}", part, text, usage), where);
        t.hidden.push_back(w);
        if (x == std::string_view::npos)
            break;
        rest = rest.substr(x + 1);
    }
    t.validate(where);
    return t;
}

void NeuralSky::validate(const std::string& where) const {
    topology.validate(where + ": topology");
    if (weights.size() != std::size_t(topology.weight_count()))
        throw Error(fmt::format("topology {} needs {} weights but the file has {}; the file is corrupt or was edited, "
                                "train it again with `skybake sky train`",
                                topology.name(), topology.weight_count(), weights.size()),
                    where);
    for (std::size_t i = 0; i < weights.size(); ++i)
        if (!std::isfinite(weights[i]))
            throw Error(fmt::format("weight {} is not a finite number; train the network again", i), where);
    // The network runs in float: max{N} must be a float far from its limits.
    if (!(std::isfinite(encoding.max_n) && encoding.max_n >= 1e-30 && encoding.max_n <= 1e30))
        throw Error("encoding.max_n must be a number in [1e-30, 1e30] (radiance per unit irradiance, 1/sr)", where);
    if ((encoding.brightness == BrightnessEncoding::Log || has_phase_terms(encoding.outputs)) &&
        !(std::isfinite(encoding.log_range) && encoding.log_range > 0.0 && encoding.log_range < 200.0))
        throw Error("encoding.log_range must be in (0, 200) nats", where);
    if (has_phase_terms(encoding.outputs)) {
        if (encoding.terms.empty() || int(encoding.terms.size()) > neural::kMaxTerms)
            throw Error(fmt::format("phase-factored outputs need 1 to {} terms, not {}", neural::kMaxTerms,
                                    encoding.terms.size()),
                        where + ": encoding.terms");
        if (encoding.brightness != BrightnessEncoding::Log)
            throw Error("phase-factored outputs are log-encoded: encoding.brightness must be log", where);
        for (const PhaseTerm& t : encoding.terms) {
            if (t.phase == PhaseFunction::None || !(std::isfinite(t.g) && std::abs(t.g) < 1.0))
                throw Error("a phase term needs a phase function and g in (-1, 1)", where + ": encoding.terms");
            for (int c = 0; c < 3; ++c)
                if (!(std::isfinite(t.max_s[c]) && t.max_s[c] >= 1e-30 && t.max_s[c] <= 1e30))
                    throw Error("a phase term's max_s must be numbers in [1e-30, 1e30]", where + ": encoding.terms");
        }
    } else if (!encoding.terms.empty()) {
        throw Error("radiance outputs have no phase terms", where + ": encoding.terms");
    }
    if (encoding.multiple) {
        if (encoding.outputs != OutputEncoding::Residual)
            throw Error("only residual outputs have a multiple-scattering term", where + ": encoding.multiple_max");
        for (int c = 0; c < 3; ++c)
            if (!(std::isfinite(encoding.multiple_max[c]) && encoding.multiple_max[c] >= 1e-30 &&
                  encoding.multiple_max[c] <= 1e30))
                throw Error("encoding.multiple_max must be numbers in [1e-30, 1e30]", where);
    }
    if (encoding.multiple_marched()) {
        const std::string pw = where + ": encoding.multiple_psi";
        if (!encoding.multiple)
            throw Error("a marched multiple-scattering term needs encoding.multiple_max", pw);
        if (encoding.multiple_psi.size() != std::size_t(3 * neural::kPsiCoefficients))
            throw Error(fmt::format("log_psi must be 3 rows of {} coefficients", neural::kPsiCoefficients), pw);
        for (double a : encoding.multiple_psi)
            if (!(std::isfinite(a) && std::abs(a) <= 1e4))
                throw Error("log_psi must be numbers in [-1e4, 1e4]", pw);
        if (!(encoding.multiple_psi_mu_min >= -0.99 && encoding.multiple_psi_mu_min <= 0.5))
            throw Error("mu_s_min must be in [-0.99, 0.5]", pw);
    }
    if (encoding.outputs == OutputEncoding::Residual)
        neural::check_residual_atmosphere(encoding, atmosphere, where);
    if (encoding.has_family())
        neural::check_family(encoding, atmosphere, where + ": encoding.family");
    if (topology.inputs != encoding.input_count())
        throw Error(fmt::format("topology.inputs is {} but the encoding has {} inputs", topology.inputs,
                                encoding.input_count()),
                    where);
    const double lo = encoding.has_family() ? encoding.aerosol_min : 1.0;
    const double hi = encoding.has_family() ? encoding.aerosol_max : 1.0;
    if (!(aerosol >= lo * (1.0 - 1e-9) && aerosol <= hi * (1.0 + 1e-9)))
        throw Error(encoding.has_family()
                        ? fmt::format("the aerosol amount {} is outside the family's range [{}, {}]", aerosol, lo, hi)
                        : fmt::format("the aerosol amount {} needs a network of an aerosol family (sky train "
                                      "--aerosol-range); this one knows only its atmosphere's (1)",
                                      aerosol),
                    where + ": aerosol");
    if (topology.outputs != encoding.output_count())
        throw Error(fmt::format("topology.outputs is {} but the {} encoding has {} outputs", topology.outputs,
                                output_encoding_name(encoding.outputs), encoding.output_count()),
                    where);
}

std::string neural_sky_to_json(const NeuralSky& net) {
    json j;
    j["format"] = kFormat;
    j["version"] = kVersion;
    const NeuralEncoding& e = net.encoding;
    const bool factored = has_phase_terms(e.outputs);
    j["topology"] = {{"name", net.topology.name()},
                     {"kind", net.topology.shared ? "shared" : "independent"},
                     {"hidden", net.topology.hidden},
                     {"outputs", net.topology.outputs},
                     {"input_meaning", std::string(e.inputs == InputEncoding::Seed
                                                       ? "cos_view_zenith, cos_view_sun, cos_sun_zenith, density"
                                                       : "view ray length split at the horizon, cos_view_sun, "
                                                         "cos_sun_zenith, altitude coordinate") +
                                           (e.has_family() ? ", aerosol amount (log, -1 to 1 over its range)" : "")},
                     {"output_meaning",
                      e.outputs == OutputEncoding::Residual
                          ? "per term, ln(S/A) for r, g, b (A: the analytic march; each as 0.5 + 0.45 value/2)"
                      : factored ? "per term, S_r, S_g, S_b (log, each as 0.05 + 0.9 value)"
                                 : "R/N, G/N, B/N, M (each as 0.05 + 0.9 value)"},
                     {"activation", "1/(1+2^(2x))"},
                     {"weight_count", net.topology.weight_count()}};
    j["encoding"] = {{"inputs", input_encoding_name(e.inputs)},
                     {"outputs", output_encoding_name(e.outputs)},
                     {"brightness", brightness_encoding_name(e.brightness)},
                     {"max_n", e.max_n},
                     {"log_range", e.log_range}};
    if (factored) {
        json terms = json::array();
        for (const PhaseTerm& t : e.terms)
            terms.push_back({{"component", t.component},
                             {"phase", phase_function_name(t.phase)},
                             {"g", t.g},
                             {"max_s", {t.max_s.x, t.max_s.y, t.max_s.z}}});
        j["encoding"]["terms"] = std::move(terms);
    }
    if (e.multiple)
        j["encoding"]["multiple_max"] = {e.multiple_max.x, e.multiple_max.y, e.multiple_max.z};
    if (e.multiple_marched()) {
        json rows = json::array();
        for (int c = 0; c < 3; ++c)
            rows.push_back(std::vector<double>(e.multiple_psi.begin() + c * neural::kPsiCoefficients,
                                               e.multiple_psi.begin() + (c + 1) * neural::kPsiCoefficients));
        j["encoding"]["multiple_psi"] = {{"mu_s_min", e.multiple_psi_mu_min}, {"log_psi", std::move(rows)}};
    }
    if (e.has_family()) {
        j["topology"]["inputs"] = net.topology.inputs;
        j["encoding"]["family"] = {{"component", e.family_component},
                                   {"aerosol_range", {e.aerosol_min, e.aerosol_max}}};
    }
    json subnets = json::array();
    const std::size_t per = std::size_t(net.topology.subnet_weight_count());
    for (int s = 0; s < net.topology.subnet_count(); ++s) {
        json w = json::array();
        for (std::size_t i = 0; i < per; ++i)
            w.push_back(double(net.weights[std::size_t(s) * per + i]));
        subnets.push_back(std::move(w));
    }
    j["weights"] = std::move(subnets);
    j["weights_layout"] = "per sub-network (R, G, B, M; or one shared), per layer: W row-major [out][in], then b [out]";
    j["atmosphere"] = json::parse(atmosphere_to_json(net.atmosphere));
    j["sky_model"] = {{"steps", net.sky_options.steps},
                      {"uniform_steps", net.sky_options.uniform_steps},
                      {"shells", net.sky_options.tables.shells},
                      {"cosines", net.sky_options.tables.cosines}};
    const NeuralTrainingSummary& t = net.training;
    j["training"] = {{"samples", t.samples},
                     {"heldout_samples", t.heldout_samples},
                     {"seed", t.seed},
                     {"adam_epochs", t.adam_epochs},
                     {"lm_iterations", t.lm_iterations},
                     {"seconds", t.seconds},
                     {"threads", t.threads},
                     {"train_rms", t.train_rms},
                     {"heldout_rms", t.heldout_rms},
                     {"heldout_mean_relative", t.heldout_mean_relative}};
    return j.dump(1) + "\n";
}

namespace {

const json& field(const json& j, const char* name, const std::string& where) {
    if (!j.is_object() || !j.contains(name))
        throw Error(fmt::format("missing field '{}'; is this a weights file written by `skybake sky train`?", name),
                    where);
    return j.at(name);
}

double number(const json& j, const char* name, const std::string& where) {
    const json& v = field(j, name, where);
    if (!v.is_number())
        throw Error(fmt::format("field '{}' must be a number", name), where);
    return v.get<double>();
}

int integer(const json& j, const char* name, const std::string& where, int lo, int hi) {
    const json& v = field(j, name, where);
    if (!v.is_number_integer() || v.get<long long>() < lo || v.get<long long>() > hi)
        throw Error(fmt::format("field '{}' must be an integer in {}..{}", name, lo, hi), where);
    return v.get<int>();
}

} // namespace

NeuralSky neural_sky_from_json(std::string_view text, const std::string& where) {
    json j;
    try {
        j = json::parse(text);
    } catch (const json::exception& e) {
        throw Error(fmt::format("not valid JSON ({}); the weights file is corrupt", e.what()), where);
    }
    if (!j.is_object() || !j.contains("format") || j["format"] != kFormat)
        throw Error(fmt::format("not a neural sky weights file (expected \"format\": \"{}\")", kFormat), where);
    if (!j.contains("version") || !j["version"].is_number_integer() || j["version"].get<long long>() < 1 ||
        j["version"].get<long long>() > kVersion)
        throw Error(fmt::format("unsupported weights file version (this build reads versions 1 to {})", kVersion),
                    where);
    const int version = j["version"].get<int>();
    NeuralSky net;
    try {
        const json& top = field(j, "topology", where);
        const json& kind = field(top, "kind", where + ": topology");
        if (kind != "independent" && kind != "shared")
            throw Error("topology.kind must be \"independent\" or \"shared\"", where);
        net.topology.shared = kind == "shared";
        const json& hidden = field(top, "hidden", where + ": topology");
        if (!hidden.is_array())
            throw Error("topology.hidden must be an array of layer widths", where);
        net.topology.hidden.clear();
        for (const json& w : hidden) {
            if (!w.is_number_integer())
                throw Error("topology.hidden must hold integers", where);
            net.topology.hidden.push_back(w.get<int>());
        }
        net.topology.validate(where + ": topology");

        const json& enc = field(j, "encoding", where);
        const json& b = field(enc, "brightness", where + ": encoding");
        if (!b.is_string())
            throw Error("encoding.brightness must be \"linear\" or \"log\"", where);
        net.encoding.brightness = parse_brightness_encoding(b.get<std::string>(), where + ": encoding.brightness");
        net.encoding.max_n = number(enc, "max_n", where + ": encoding");
        net.encoding.log_range = number(enc, "log_range", where + ": encoding");
        if (version >= 2) { // version 1: the seed's inputs and radiance outputs
            const json& in = field(enc, "inputs", where + ": encoding");
            const json& out = field(enc, "outputs", where + ": encoding");
            if (!in.is_string() || !out.is_string())
                throw Error("encoding.inputs and encoding.outputs must be names", where);
            net.encoding.inputs = parse_input_encoding(in.get<std::string>(), where + ": encoding.inputs");
            if (version == 2 && net.encoding.inputs == InputEncoding::Horizon)
                throw Error("version 2 horizon inputs had no zenith-nadir gap and are no longer read; retrain the "
                            "network with this version",
                            where + ": encoding.inputs");
            net.encoding.outputs = parse_output_encoding(out.get<std::string>(), where + ": encoding.outputs");
            if (has_phase_terms(net.encoding.outputs)) {
                const json& terms = field(enc, "terms", where + ": encoding");
                if (!terms.is_array() || terms.empty() || int(terms.size()) > neural::kMaxTerms)
                    throw Error(fmt::format("encoding.terms must be an array of 1 to {} terms", neural::kMaxTerms),
                                where);
                for (const json& t : terms) {
                    const std::string tw = where + ": encoding.terms";
                    PhaseTerm p;
                    const json& c = field(t, "component", tw);
                    const json& ph = field(t, "phase", tw);
                    const json& mx = field(t, "max_s", tw);
                    if (!c.is_string() || !ph.is_string() || !mx.is_array() || mx.size() != 3 ||
                        !mx[0].is_number() || !mx[1].is_number() || !mx[2].is_number())
                        throw Error("a term needs a component name, a phase name, g and max_s [r, g, b]", tw);
                    p.component = c.get<std::string>();
                    p.phase = parse_phase_function(ph.get<std::string>(), tw + ".phase");
                    p.g = number(t, "g", tw);
                    p.max_s = glm::dvec3(mx[0].get<double>(), mx[1].get<double>(), mx[2].get<double>());
                    net.encoding.terms.push_back(p);
                }
            }
            if (enc.contains("multiple_max")) {
                const json& mm = enc["multiple_max"];
                if (!mm.is_array() || mm.size() != 3 || !mm[0].is_number() || !mm[1].is_number() ||
                    !mm[2].is_number())
                    throw Error("encoding.multiple_max must be [r, g, b]", where);
                net.encoding.multiple = true;
                net.encoding.multiple_max = glm::dvec3(mm[0].get<double>(), mm[1].get<double>(), mm[2].get<double>());
            }
            if (enc.contains("multiple_psi")) {
                const std::string pw = where + ": encoding.multiple_psi";
                const json& mp = enc["multiple_psi"];
                const json& rows = field(mp, "log_psi", pw);
                if (!rows.is_array() || rows.size() != 3)
                    throw Error("log_psi must be 3 rows of coefficients", pw);
                net.encoding.multiple_psi_mu_min = number(mp, "mu_s_min", pw);
                for (const json& row : rows) {
                    if (!row.is_array() || row.size() != std::size_t(neural::kPsiCoefficients))
                        throw Error(fmt::format("log_psi must be 3 rows of {} coefficients", neural::kPsiCoefficients),
                                    pw);
                    for (const json& a : row) {
                        if (!a.is_number())
                            throw Error("log_psi must hold numbers", pw);
                        net.encoding.multiple_psi.push_back(a.get<double>());
                    }
                }
            }
            if (enc.contains("family")) {
                const std::string fw = where + ": encoding.family";
                const json& f = enc["family"];
                const json& c = field(f, "component", fw);
                const json& r = field(f, "aerosol_range", fw);
                if (!c.is_string() || c.get<std::string>().empty() || !r.is_array() || r.size() != 2 ||
                    !r[0].is_number() || !r[1].is_number())
                    throw Error("encoding.family needs a component name and aerosol_range [min, max]", fw);
                net.encoding.family_component = c.get<std::string>();
                net.encoding.aerosol_min = r[0].get<double>();
                net.encoding.aerosol_max = r[1].get<double>();
                net.topology.inputs = integer(top, "inputs", where + ": topology", neural::kInputs, neural::kMaxInputs);
            }
            net.topology.outputs = integer(top, "outputs", where + ": topology", 1, neural::kMaxOutputs);
            if (net.topology.outputs != net.encoding.output_count())
                throw Error(fmt::format("topology.outputs is {} but the encoding has {} outputs",
                                        net.topology.outputs, net.encoding.output_count()),
                            where);
        }

        const json& w = field(j, "weights", where);
        if (!w.is_array())
            throw Error(fmt::format("'weights' is {}, not an array of {} sub-network arrays", w.type_name(),
                                    net.topology.subnet_count()),
                        where);
        if (int(w.size()) != net.topology.subnet_count())
            throw Error(fmt::format("'weights' must hold {} sub-network arrays for topology {}, holds {}",
                                    net.topology.subnet_count(), net.topology.name(), w.size()),
                        where);
        for (std::size_t s = 0; s < w.size(); ++s) {
            if (!w[s].is_array())
                throw Error(fmt::format("sub-network {} is {}, not an array of {} weights", s, w[s].type_name(),
                                        net.topology.subnet_weight_count()),
                            where);
            if (int(w[s].size()) != net.topology.subnet_weight_count())
                throw Error(fmt::format("sub-network {} must have {} weights for topology {}, has {}; the file is "
                                        "corrupt or does not match its topology",
                                        s, net.topology.subnet_weight_count(), net.topology.name(), w[s].size()),
                            where);
            for (const json& v : w[s]) {
                if (!v.is_number())
                    throw Error(fmt::format("sub-network {} holds a weight that is not a number", s), where);
                net.weights.push_back(float(v.get<double>()));
            }
        }
        net.atmosphere = atmosphere_from_json(field(j, "atmosphere", where).dump(), where + ": atmosphere");
        const json& sm = field(j, "sky_model", where);
        net.sky_options.steps = integer(sm, "steps", where + ": sky_model", 1, 1 << 20);
        net.sky_options.tables.shells = integer(sm, "shells", where + ": sky_model", 2, 1 << 14);
        net.sky_options.tables.cosines = integer(sm, "cosines", where + ": sky_model", 2, 1 << 14);
        const json& us = field(sm, "uniform_steps", where + ": sky_model");
        if (!us.is_boolean())
            throw Error("sky_model.uniform_steps must be true or false", where);
        net.sky_options.uniform_steps = us.get<bool>();
        if (j.contains("training") && j["training"].is_object()) {
            const json& t = j["training"];
            NeuralTrainingSummary& s = net.training;
            s.samples = t.value("samples", std::uint64_t(0));
            s.heldout_samples = t.value("heldout_samples", std::uint64_t(0));
            s.seed = t.value("seed", std::uint64_t(0));
            s.adam_epochs = t.value("adam_epochs", 0);
            s.lm_iterations = t.value("lm_iterations", 0);
            s.seconds = t.value("seconds", 0.0);
            s.threads = t.value("threads", 0);
            s.train_rms = t.value("train_rms", 0.0);
            s.heldout_rms = t.value("heldout_rms", 0.0);
            s.heldout_mean_relative = t.value("heldout_mean_relative", 0.0);
        }
    } catch (const json::exception& e) {
        throw Error(fmt::format("malformed weights file ({})", e.what()), where);
    }
    net.validate(where);
    return net;
}

NeuralSky load_neural_sky(const std::filesystem::path& path) {
    return neural_sky_from_json(read_file(path, std::uint64_t(1) << 28), path.string());
}

void save_neural_sky(const std::filesystem::path& path, const NeuralSky& net) {
    net.validate("neural sky");
    const std::string text = neural_sky_to_json(net);
    write_stream_atomic(path, [&](std::ostream& out) { out << text; });
}

SkyModel neural_reference_model(const NeuralSky& net) {
    if (net.encoding.has_family() && net.aerosol != 1.0)
        return SkyModel(neural::scaled_atmosphere(net.encoding, net.atmosphere, net.aerosol), net.sky_options);
    return SkyModel(net.atmosphere, net.sky_options);
}

namespace {
constexpr NamedValue<BrightnessEncoding> kBrightnessNames[] = {
    {BrightnessEncoding::Linear, "linear", "the paper's", "seed"},
    {BrightnessEncoding::Log, "log", "a fixed relative error over many decades"},
};
constexpr NamedValue<InputEncoding> kInputNames[] = {
    {InputEncoding::Seed, "seed", "(cos a0, cos b0, cos t0, rho0) as in the seed"},
    {InputEncoding::Horizon, "horizon", "ray length split at the horizon, cos b0, cos t0, altitude"},
};
constexpr NamedValue<OutputEncoding> kOutputNames[] = {
    {OutputEncoding::Radiance, "radiance", "R/N, G/N, B/N and brightness, as in the seed"},
    {OutputEncoding::PhaseFactored, "phase-factored", "phase-free in-scatter per component, exact phase outside"},
    {OutputEncoding::Residual, "residual", "phase-factored, as corrections of an analytic few-step march"},
};
} // namespace

const char* input_encoding_name(InputEncoding encoding) { return name_of(kInputNames, encoding); }
const char* output_encoding_name(OutputEncoding encoding) { return name_of(kOutputNames, encoding); }
InputEncoding parse_input_encoding(const std::string& text, const std::string& where) {
    return parse_name(kInputNames, text, "input encoding", where);
}
OutputEncoding parse_output_encoding(const std::string& text, const std::string& where) {
    return parse_name(kOutputNames, text, "output encoding", where);
}

const char* brightness_encoding_name(BrightnessEncoding encoding) { return name_of(kBrightnessNames, encoding); }

BrightnessEncoding parse_brightness_encoding(const std::string& text, const std::string& where) {
    return parse_name(kBrightnessNames, text, "brightness encoding", where);
}

} // namespace skybake
