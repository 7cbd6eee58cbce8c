// Accuracy of a neural sky against the sky model it approximates (Pietras &
// Rudnicki, seed 000, sections III and VII): relative RGB error on held-out
// random samples, split into day, twilight and night, and the PSNR of the
// seed's views rendered with the network against the same views from the
// model's marching sum.
#include <algorithm>
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include <glm/geometric.hpp>

#include "neural/internal.h"
#include "skybake/error.h"
#include "skybake/image_io.h"

namespace skybake {

ErrorStats error_stats(std::vector<double>& e) {
    ErrorStats s;
    s.count = e.size();
    if (e.empty())
        return s;
    std::sort(e.begin(), e.end());
    double sum = 0.0;
    for (double v : e)
        sum += v;
    s.mean = sum / double(e.size());
    auto pct = [&](double p) { // nearest rank
        const std::size_t k = std::size_t(std::ceil(p * double(e.size())));
        return e[std::min(e.size() - 1, k == 0 ? 0 : k - 1)];
    };
    s.p50 = pct(0.50);
    s.p95 = pct(0.95);
    s.p99 = pct(0.99);
    s.max = e.back();
    return s;
}

NeuralErrorReport neural::measure_approximation_error(const SkyModel& model, double max_n,
                                                     const NeuralErrorOptions& o, const BatchSky& evaluate,
                                                     const RenderSky& render, const NeuralEncoding* family) {
    if (o.samples < 1 || o.samples > (std::size_t(1) << 28))
        throw Error("the number of samples must be 1 to 2^28", "samples");
    if (o.views && (o.view_width < 1 || o.view_height < 1 || o.view_width > 4096 || o.view_height > 4096))
        throw Error("view size must be 1 to 4096 pixels on each side", "view_width/view_height");
    if (o.flight_samples > (std::size_t(1) << 28))
        throw Error("the number of flight samples must be 0 to 2^28", "flight_samples");
    NeuralErrorReport rep;
    // Relative errors of `samples`, split into all lit, day and twilight, and night.
    const auto measure = [&](const std::vector<SkySample>& samples, ErrorStats& all_s, ErrorStats& day_s,
                             ErrorStats& twilight_s, ErrorStats& night_s) {
        std::vector<glm::vec3> ref(samples.size()), got(samples.size());
        std::vector<float> aerosol;
        if (family) { // each sample's amount, from a stream of the held-out seed and the set's size
            aerosol = draw_aerosol(*family, samples.size(), o.seed ^ (std::uint64_t(samples.size()) << 20));
            std::vector<glm::vec3> split;
            scaled_sky_targets(model, samples, aerosol, family_component_index(*family, model.atmosphere()), split,
                               ref);
        } else {
            evaluate_sky(model, samples, ref, SkyMethod::Tables);
        }
        evaluate(samples, aerosol, got);
        std::vector<double> all, day, twilight, night;
        for (std::size_t i = 0; i < samples.size(); ++i) {
            const glm::dvec3 r(ref[i]), g(got[i]);
            const double err = glm::length(g - r);
            if (!(std::max({r.x, r.y, r.z}) > 0.0)) {
                night.push_back(err / max_n);
                continue;
            }
            const double rel = err / glm::length(r);
            all.push_back(rel);
            (samples[i].cos_sun_zenith > 0.0f ? day : twilight).push_back(rel);
        }
        all_s = error_stats(all);
        day_s = error_stats(day);
        twilight_s = error_stats(twilight);
        night_s = error_stats(night);
    };
    measure(draw_sky_samples(o.samples, o.seed), rep.all, rep.day, rep.twilight, rep.night);
    if (o.flight_samples > 0)
        measure(draw_flight_samples(o.flight_samples, o.seed, model.atmosphere(), o.flight), rep.flight_all,
                rep.flight_day, rep.flight_twilight, rep.flight_night);

    if (o.views) {
        if (!o.views_dir.empty())
            std::filesystem::create_directories(o.views_dir);
        double sum = 0.0, mn = INFINITY;
        // A family's views at the ends of its range and its geometric middle.
        std::vector<double> amounts{1.0};
        if (family)
            amounts = {family->aerosol_min, std::sqrt(family->aerosol_min * family->aerosol_max), family->aerosol_max};
        for (double amount : amounts) {
            std::optional<SkyModel> scaled;
            if (family)
                scaled.emplace(scaled_atmosphere(*family, model.atmosphere(), amount), model.options());
            for (const PublishedView& v : published_views(o.view_width, o.view_height)) {
                const SkyModel& reference = scaled ? *scaled : model;
                const Image a = render_sky(reference, v.settings);
                const Image b = render(v.settings, amount, reference);
                ToneMap tm;
                tm.exposure_ev = float(auto_exposure_ev(a));
                const double psnr = image_psnr_db(a, b, tm);
                const std::string name = family ? fmt::format("{}_aerosol_{:.3g}", v.name, amount) : v.name;
                rep.views.push_back({name, psnr});
                sum += psnr;
                mn = std::min(mn, psnr);
                if (!o.views_dir.empty()) {
                    save_image(o.views_dir / (name + "_reference.png"), a, tm);
                    save_image(o.views_dir / (name + "_neural.png"), b, tm);
                }
            }
        }
        rep.mean_view_psnr_db = sum / double(rep.views.size());
        rep.min_view_psnr_db = mn;
    }
    return rep;
}

NeuralErrorReport measure_neural_sky_error(const NeuralSky& net, const NeuralErrorOptions& o) {
    net.validate("neural sky");
    NeuralSky base = net; // a family's samples and views choose their own amounts
    base.aerosol = 1.0;
    const SkyModel model = neural_reference_model(base);
    return neural::measure_approximation_error(
        model, net.encoding.max_n, o,
        [&](std::span<const SkySample> s, std::span<const float> aerosol, std::span<glm::vec3> out) {
            neural::evaluate_neural_sky_at(net, s, aerosol, out);
        },
        [&](const SkyRenderSettings& v, double aerosol, const SkyModel& tables) {
            NeuralSky at = net;
            at.aerosol = aerosol;
            return render_neural_sky(at, tables, v);
        },
        net.encoding.has_family() ? &net.encoding : nullptr);
}

} // namespace skybake
