// Measures both multiple-scattering methods against the Monte Carlo path
// tracer over a grid of views on Earth: observers at 0, 10, 50 and 100 km;
// suns at 60, 10, 2, 0, −4, −8, −12 and −16°; the zenith and the
// horizon towards and away from the sun (docs/sky.md, "Error over a grid of
// views", is this program's output).
//
//   twilight_report [--paths N] [--twilight-paths N] [--reference FILE] [--nr N] [--nmus N] [--mu-s-min C] [--sphere N] [--nu N] [--orders N]
//   twilight_report --night [--twilight-paths N] [--nr N] [--nmus N] [--mu-s-min C] [--orders N]
//   (--altitude H and --sun S keep only the views at H km, at S°)
//
// The reference is the exact single-scattering quadrature plus the path
// tracer's orders 2 and up (all of them): with the sun's next events and
// --paths paths per channel (default 2^16) where the sun is up, and with next
// events through the sunlit air (NextEvent::SunlitAir), which resolve the sky
// beyond the terminator, and --twilight-paths (default 2^14) where it is
// down. --reference FILE reads it from FILE
// when FILE exists, else traces it and writes it there, so table settings can
// be compared against one reference. The horizon is the direction 1° above
// the geometric horizon (for an observer above the atmosphere, 1° above the
// planet's limb); the zenith from above the atmosphere sees no air and is
// left out. Columns: % error of the total radiance, R, G, B, and three
// standard errors of the reference in % of it; a channel whose three
// standard errors exceed 30% of the reference (deep twilight, where paths
// seldom find the lit air), or that is 0 (none did), is not compared ("·"). Built as a tool, not a test:
// the reference takes minutes. --night prints instead the orders' zenith
// radiance at sea level for suns from 0 to −30° (how the night falls); with
// --twilight-paths, next to the path tracer's (all orders) from −4° to −24°.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "skybake/sky.h"
#include "skybake/sky_path_tracer.h"

using namespace skybake;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

struct View {
    double altitude_km, sun_deg;
    int kind; // 0 zenith, 1 horizon towards the sun, 2 horizon away from it
    double mu, nu, mu_s;
};

const char* kKinds[] = {"zenith", "horizon, towards the sun", "horizon, away from the sun"};

std::vector<View> grid(double R0, double Rt) {
    std::vector<View> views;
    for (double h : {0.0, 10.0, 50.0, 100.0})
        for (double sun : {60.0, 10.0, 2.0, 0.0, -4.0, -8.0, -12.0, -16.0})
            for (int kind = 0; kind < 3; ++kind) {
                const double r = R0 + h;
                if (kind == 0 && r >= Rt)
                    continue;
                const double ts = (90.0 - sun) * kDeg; // sun zenith angle
                double tv = 0.0;                          // view zenith angle
                if (kind > 0)
                    tv = kPi - std::asin(R0 / r) - 1.0 * kDeg; // 1° above the geometric horizon
                const double mu = std::cos(tv), mu_s = std::cos(ts);
                // Same azimuth as the sun (towards) or the opposite one (away).
                const double nu = kind == 2 ? std::cos(tv + ts) : std::cos(tv - ts);
                views.push_back({h, sun, kind, mu, nu, mu_s});
            }
    return views;
}

SkyModel multiple_model(const Atmosphere& earth, MultipleScatteringMethod method, int orders,
                        const MultipleScatteringResolution& res) {
    Atmosphere atm = earth;
    atm.scattering = Scattering::Multiple;
    atm.multiple_method = method;
    atm.scattering_orders = orders;
    SkyModelOptions options;
    options.multiple = res;
    return SkyModel(atm, options);
}

std::string key(const View& v) { return fmt::format("{} {} {}", v.altitude_km, v.sun_deg, v.kind); }

} // namespace

int main(int argc, char** argv) {
    std::uint64_t paths = 1u << 16;
    std::string reference_file;
    MultipleScatteringResolution res;
    int orders = 4;
    bool night = false;
    std::uint64_t twilight_paths = 1u << 14;
    bool night_reference = false;
    double only_altitude = -1.0, only_sun = 1000.0;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--night") {
            night = true;
            continue;
        }
        const char* value = i + 1 < argc ? argv[i + 1] : nullptr;
        if (!value) {
            std::fprintf(stderr, "twilight_report: %s needs a value\n", a.c_str());
            return 2;
        }
        if (a == "--paths")
            paths = std::strtoull(value, nullptr, 10);
        else if (a == "--twilight-paths") {
            twilight_paths = std::strtoull(value, nullptr, 10);
            night_reference = true;
        }
        else if (a == "--reference")
            reference_file = value;
        else if (a == "--nmus")
            res.mu_s = std::atoi(value);
        else if (a == "--nr")
            res.r = std::atoi(value);
        else if (a == "--sphere")
            res.sphere = std::atoi(value);
        else if (a == "--nu")
            res.nu = std::atoi(value);
        else if (a == "--mu-s-min")
            res.mu_s_min = std::atof(value);
        else if (a == "--altitude")
            only_altitude = std::atof(value);
        else if (a == "--sun")
            only_sun = std::atof(value);
        else if (a == "--orders")
            orders = std::atoi(value);
        else {
            std::fprintf(stderr, "twilight_report: unknown option %s\n", a.c_str());
            return 2;
        }
        ++i;
    }
    try {
        const Atmosphere earth = atmosphere_preset("earth");
        const double R0 = earth.planet_radius_km, Rt = earth.top_radius_km;
        std::vector<View> views;
        for (const View& v : grid(R0, Rt))
            if ((only_altitude < 0.0 || v.altitude_km == only_altitude) && (only_sun > 999.0 || v.sun_deg == only_sun))
                views.push_back(v);
        if (night) {
            const SkyModel model = multiple_model(earth, MultipleScatteringMethod::Orders, orders, res);
            if (!night_reference) {
                std::printf("| sun | zenith radiance at sea level (R, G, B) |\n|---|---|\n");
                for (int deg = 0; deg >= -30; --deg) {
                    const double mu_s = std::cos((90.0 - deg) * kDeg);
                    const glm::dvec3 L = model.radiance_at_radius(R0, 1.0, mu_s, mu_s, SkyMethod::Exact);
                    std::printf("| %d° | %.3g, %.3g, %.3g |\n", deg, L.x, L.y, L.z);
                }
                return 0;
            }
            // With --twilight-paths: against the path tracer, every order.
            PathTracerOptions pt;
            pt.paths = twilight_paths;
            pt.next_event = NextEvent::SunlitAir;
            std::printf("| sun | orders %d (R, G, B) | path tracer (R, G, B) | ratio | 3σ of the reference, %% |\n"
                        "|---|---|---|---|---|\n",
                        orders);
            for (const int deg : {-4, -8, -12, -16, -18, -20, -24}) {
                if (only_sun < 999.0 && double(deg) != only_sun)
                    continue;
                const double mu_s = std::cos((90.0 - deg) * kDeg);
                const glm::dvec3 L = model.radiance_at_radius(R0, 1.0, mu_s, mu_s, SkyMethod::Exact);
                const PathTracedRadiance m = path_trace_sky(earth, R0, 1.0, mu_s, mu_s, pt);
                const glm::dvec3 q = L / m.mean, e = 300.0 * m.standard_error / m.mean;
                std::printf("| %d° | %.2g, %.2g, %.2g | %.2g, %.2g, %.2g | %.2f, %.2f, %.2f | %.0f, %.0f, %.0f |\n", deg,
                            L.x, L.y, L.z, m.mean.x, m.mean.y, m.mean.z, q.x, q.y, q.z, e.x, e.y, e.z);
                std::fflush(stdout);
            }
            return 0;
        }

        // The reference: exact single scattering + traced orders ≥ 2.
        std::map<std::string, std::pair<glm::dvec3, glm::dvec3>> ref; // total, standard error
        if (!reference_file.empty()) {
            std::ifstream in(reference_file);
            std::string line;
            while (std::getline(in, line)) {
                double h, s, k, t[3], e[3];
                if (std::sscanf(line.c_str(), "%lf %lf %lf %lg %lg %lg %lg %lg %lg", &h, &s, &k, &t[0], &t[1], &t[2],
                                &e[0], &e[1], &e[2]) == 9)
                    ref[fmt::format("{} {} {}", h, s, int(k))] = {{t[0], t[1], t[2]}, {e[0], e[1], e[2]}};
            }
        }
        const SkyModel single(earth);
        PathTracerOptions pt;
        pt.min_order = 2;
        bool traced = false;
        for (const View& v : views) {
            if (ref.count(key(v)))
                continue;
            const glm::dvec3 s = single.radiance_at_radius(R0 + v.altitude_km, v.mu, v.nu, v.mu_s, SkyMethod::Exact);
            const bool sun_down = v.mu_s < 0.0;
            pt.paths = sun_down ? twilight_paths : paths;
            pt.next_event = sun_down ? NextEvent::SunlitAir : NextEvent::Sun;
            const PathTracedRadiance m = path_trace_sky(earth, R0 + v.altitude_km, v.mu, v.nu, v.mu_s, pt);
            ref[key(v)] = {s + m.mean, m.standard_error};
            traced = true;
            std::fprintf(stderr, ".");
        }
        if (traced && !reference_file.empty()) {
            std::ofstream out(reference_file);
            for (const View& v : views) {
                const auto& [t, e] = ref[key(v)];
                out << fmt::format("{} {} {} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g}\n", v.altitude_km, v.sun_deg,
                                   v.kind, t.x, t.y, t.z, e.x, e.y, e.z);
            }
        }

        const SkyModel by_orders = multiple_model(earth, MultipleScatteringMethod::Orders, orders, res);
        const SkyModel by_hillaire = multiple_model(earth, MultipleScatteringMethod::Hillaire, orders, res);

        std::printf("| altitude | sun | view | reference total (R, G, B) | orders %d, %% | hillaire, %% | 3σ of the reference, %% |\n",
                    orders);
        std::printf("|---|---|---|---|---|---|---|\n");
        double worst_orders = 0.0;
        for (const View& v : views) {
            const auto& [t, e] = ref[key(v)];
            const glm::dvec3 o = by_orders.radiance_at_radius(R0 + v.altitude_km, v.mu, v.nu, v.mu_s, SkyMethod::Exact);
            const glm::dvec3 hl =
                by_hillaire.radiance_at_radius(R0 + v.altitude_km, v.mu, v.nu, v.mu_s, SkyMethod::Exact);
            // A standard error of 0: no path found light of order 2 or more.
            auto resolved = [&](int c) { return e[c] > 0.0 && 3.0 * e[c] <= 0.3 * t[c]; };
            auto pct = [&](const glm::dvec3& x) {
                std::string s;
                for (int c = 0; c < 3; ++c)
                    s += (c ? ", " : "") + (resolved(c) ? fmt::format("{:+.1f}", 100 * (x[c] / t[c] - 1)) : "·");
                return s;
            };
            auto sigma = [&](int c) { return t[c] > 0.0 ? fmt::format("{:.1f}", 300 * e[c] / t[c]) : "·"; };
            for (int c = 0; c < 3; ++c)
                if (resolved(c))
                    worst_orders = std::max(worst_orders, std::abs(o[c] / t[c] - 1));
            std::printf("| %g km | %g° | %s | %.3g, %.3g, %.3g | %s | %s | %s, %s, %s |\n", v.altitude_km, v.sun_deg,
                        kKinds[v.kind], t.x, t.y, t.z, pct(o).c_str(), pct(hl).c_str(), sigma(0).c_str(),
                        sigma(1).c_str(), sigma(2).c_str());
        }
        std::fprintf(stderr, "\nlargest |error| of the orders where the reference is resolved: %.1f%%\n", 100 * worst_orders);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "twilight_report: %s\n", e.what());
        return 1;
    }
    return 0;
}
