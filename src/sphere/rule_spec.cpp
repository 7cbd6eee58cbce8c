// Rule specs ("lebedev:5810", "design:t21", ...): parsing, canonical text, and
// the factory that builds the rule a spec names.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/names.h"
#include "skybake/sphere.h"

namespace skybake {

namespace {

constexpr int kMaxPoints = 1 << 24; // mc / fibonacci
constexpr int kMaxDesignT = 40;
constexpr int kMaxPhongNodes = 512;

const char* const kForms =
    "expected one of mc:N[,seed=S], fibonacci:N, lebedev:N, lebedev:pP, design:tT, phong:a=A,n=N, horizon:NxM, "
    "optionally followed by +rotate or +rotate=SEED";

[[noreturn]] void bad(const std::string& text, const std::string& why) {
    throw Error(fmt::format("bad rule spec '{}': {}", text, why), "rule spec");
}

bool parse_int(std::string_view s, long long& out) {
    if (s.empty())
        return false;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
    return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool parse_u64(std::string_view s, std::uint64_t& out) {
    if (s.empty())
        return false;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
    return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool parse_double(std::string_view s, double& out) {
    if (s.empty())
        return false;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
    return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(out);
}

std::vector<std::string_view> split(std::string_view s, char sep) {
    std::vector<std::string_view> parts;
    std::size_t start = 0;
    for (;;) {
        const std::size_t p = s.find(sep, start);
        parts.push_back(s.substr(start, p == std::string_view::npos ? std::string_view::npos : p - start));
        if (p == std::string_view::npos)
            return parts;
        start = p + 1;
    }
}

std::string lebedev_list() {
    std::string points, precisions;
    for (const LebedevInfo& r : lebedev_rules()) {
        points += fmt::format("{}{}", points.empty() ? "" : ", ", r.points);
        precisions += fmt::format("{}p{}", precisions.empty() ? "" : ", ", r.precision);
    }
    return fmt::format("available point counts are {} (or precisions {})", points, precisions);
}

} // namespace

namespace {
constexpr NamedValue<RuleKind> kRuleKindNames[] = {
    {RuleKind::MonteCarlo, "mc"}, {RuleKind::Fibonacci, "fibonacci"}, {RuleKind::Lebedev, "lebedev"},
    {RuleKind::Design, "design"}, {RuleKind::Phong, "phong"}, {RuleKind::Horizon, "horizon"},
};
} // namespace

const char* rule_kind_name(RuleKind kind) { return name_of(kRuleKindNames, kind); }

std::string RuleSpec::canonical() const {
    std::string s;
    switch (kind) {
    case RuleKind::MonteCarlo:
        s = seed == 1 ? fmt::format("mc:{}", count) : fmt::format("mc:{},seed={}", count, seed);
        break;
    case RuleKind::Fibonacci: s = fmt::format("fibonacci:{}", count); break;
    case RuleKind::Lebedev: {
        int points = 0;
        for (const LebedevInfo& r : lebedev_rules())
            if (r.precision == precision)
                points = r.points;
        s = fmt::format("lebedev:{}", points);
        break;
    }
    case RuleKind::Design: s = fmt::format("design:t{}", precision); break;
    case RuleKind::Phong: s = fmt::format("phong:a={},n={}", phong_exponent, phong_nodes); break;
    case RuleKind::Horizon: s = fmt::format("horizon:{}x{}", horizon_nodes, horizon_azimuths); break;
    }
    if (rotate)
        s += rotation_seed == 0 ? "+rotate" : fmt::format("+rotate={}", rotation_seed);
    return s;
}

RuleSpec parse_rule_spec(const std::string& text) {
    RuleSpec spec;
    std::string_view body = text;
    // Suffix "+rotate[=SEED]".
    if (const std::size_t plus = body.find('+'); plus != std::string_view::npos) {
        const std::string_view suffix = body.substr(plus + 1);
        body = body.substr(0, plus);
        spec.rotate = true;
        if (suffix == "rotate") {
            spec.rotation_seed = 0;
        } else if (suffix.substr(0, 7) == "rotate=") {
            if (!parse_u64(suffix.substr(7), spec.rotation_seed))
                bad(text, "the rotation seed after '+rotate=' must be a non-negative integer");
        } else {
            bad(text, fmt::format("unknown suffix '+{}'; the only suffix is +rotate or +rotate=SEED", suffix));
        }
    }
    const std::size_t colon = body.find(':');
    if (colon == std::string_view::npos)
        bad(text, kForms);
    const std::string_view family = body.substr(0, colon);
    const std::string_view args = body.substr(colon + 1);
    long long v = 0;

    if (family == "mc" || family == "fibonacci") {
        spec.kind = family == "mc" ? RuleKind::MonteCarlo : RuleKind::Fibonacci;
        const auto parts = split(args, ',');
        if (!parse_int(parts[0], v) || v < 1 || v > kMaxPoints)
            bad(text, fmt::format("the point count must be an integer from 1 to {}", kMaxPoints));
        spec.count = int(v);
        for (std::size_t i = 1; i < parts.size(); ++i) {
            if (spec.kind == RuleKind::MonteCarlo && parts[i].substr(0, 5) == "seed=") {
                if (!parse_u64(parts[i].substr(5), spec.seed))
                    bad(text, "the seed must be a non-negative integer");
            } else {
                bad(text, fmt::format("unknown option '{}'; {} takes {}", parts[i], family,
                                      spec.kind == RuleKind::MonteCarlo ? "only seed=S" : "no options"));
            }
        }
        return spec;
    }
    if (family == "lebedev") {
        spec.kind = RuleKind::Lebedev;
        const bool by_precision = !args.empty() && (args[0] == 'p' || args[0] == 'P');
        if (!parse_int(by_precision ? args.substr(1) : args, v))
            bad(text, lebedev_list());
        for (const LebedevInfo& r : lebedev_rules())
            if ((by_precision && r.precision == v) || (!by_precision && r.points == v))
                spec.precision = r.precision;
        if (spec.precision == 0)
            bad(text, fmt::format("no Lebedev rule has {} {}; {}", by_precision ? "precision" : "point count", v,
                                  lebedev_list()));
        return spec;
    }
    if (family == "design") {
        spec.kind = RuleKind::Design;
        const bool has_t = !args.empty() && (args[0] == 't' || args[0] == 'T');
        if (!parse_int(has_t ? args.substr(1) : args, v) || v < 1 || v > kMaxDesignT)
            bad(text, fmt::format("expected design:tT with strength T from 1 to {} (e.g. design:t21)", kMaxDesignT));
        spec.precision = int(v);
        return spec;
    }
    if (family == "phong") {
        spec.kind = RuleKind::Phong;
        bool have_a = false, have_n = false;
        for (std::string_view part : split(args, ',')) {
            if (part.substr(0, 2) == "a=") {
                if (!parse_double(part.substr(2), spec.phong_exponent) || spec.phong_exponent < 0 ||
                    spec.phong_exponent > 1e6)
                    bad(text, "the Phong exponent a must be a number from 0 to 1e6");
                have_a = true;
            } else if (part.substr(0, 2) == "n=") {
                if (!parse_int(part.substr(2), v) || v < 1 || v > kMaxPhongNodes)
                    bad(text, fmt::format("n (nodes in cos θ) must be an integer from 1 to {}", kMaxPhongNodes));
                spec.phong_nodes = int(v);
                have_n = true;
            } else {
                bad(text, fmt::format("unknown option '{}'; expected phong:a=A,n=N (e.g. phong:a=32,n=8)", part));
            }
        }
        if (!have_a || !have_n)
            bad(text, "expected phong:a=A,n=N with both the exponent a and the node count n (e.g. phong:a=32,n=8)");
        return spec;
    }
    if (family == "horizon") {
        spec.kind = RuleKind::Horizon;
        const std::size_t x = args.find('x');
        long long m = 0;
        if (x == std::string_view::npos || !parse_int(args.substr(0, x), v) || !parse_int(args.substr(x + 1), m) ||
            v < 1 || v > kMaxPhongNodes || m < 1 || m > 4096)
            bad(text, fmt::format("expected horizon:NxM with N (nodes in y per side) from 1 to {} and M (azimuths) "
                                  "from 1 to 4096 (e.g. horizon:32x48)",
                                  kMaxPhongNodes));
        spec.horizon_nodes = int(v);
        spec.horizon_azimuths = int(m);
        return spec;
    }
    bad(text, fmt::format("unknown rule family '{}'; {}", family, kForms));
}

SphereRule make_rule(const RuleSpec& spec) {
    SphereRule rule;
    switch (spec.kind) {
    case RuleKind::MonteCarlo: rule = marsaglia_rule(spec.count, spec.seed); break;
    case RuleKind::Fibonacci: rule = fibonacci_rule(spec.count); break;
    case RuleKind::Lebedev: rule = lebedev_rule_by_precision(spec.precision); break;
    case RuleKind::Design: rule = design_rule(spec.precision); break;
    case RuleKind::Phong: rule = phong_rule(spec.phong_exponent, spec.phong_nodes); break;
    case RuleKind::Horizon: rule = horizon_rule(spec.horizon_nodes, spec.horizon_azimuths); break;
    }
    rule.spec = spec.canonical();
    rule.rotate_per_vertex = spec.rotate;
    rule.rotation_seed = spec.rotation_seed;
    return rule;
}

SphereRule parse_rule(const std::string& text) { return make_rule(parse_rule_spec(text)); }

bool SphereRule::has_negative_weights() const {
    return std::any_of(weights.begin(), weights.end(), [](double w) { return w < 0.0; });
}

std::vector<glm::vec3> SphereRule::points_f32() const {
    std::vector<glm::vec3> out(points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
        out[i] = glm::vec3(points[i]);
    return out;
}

std::vector<float> SphereRule::weights_f32() const {
    return std::vector<float>(weights.begin(), weights.end());
}

} // namespace skybake
