// The size–accuracy curve of docs/neural.md: for every encoding, networks of
// about 300 to 20,000 weights trained on `earth`, and beside each a plain 4D
// look-up table of the same number of floats over the same inputs
// (SkyLookupTable), all measured by measure_neural_sky_error's views and
// 20,000 of its held-out samples. An accuracy measurement, not a timing.
//
//   neural_size_report OUT_DIR [--quick]
//
// Writes OUT_DIR/neural_size.csv and the charts neural_size_error.png and
// neural_size_psnr.png. --quick trains a tenth of the samples (a smoke run).
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/neural.h"

using namespace skybake;

namespace {

struct Encoding {
    const char* name;
    InputEncoding inputs;
    OutputEncoding outputs;
    glm::vec3 colour;
};

struct Size {
    const char* topology; // for 4 outputs; "paper" is the seed's
    int epochs, lm;
};

} // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: neural_size_report OUT_DIR [--quick]\n");
        return 2;
    }
    const std::filesystem::path out = argv[1];
    const bool quick = argc > 2 && std::strcmp(argv[2], "--quick") == 0;
    try {
        std::filesystem::create_directories(out);
        const Encoding encodings[] = {
            {"seed/radiance", InputEncoding::Seed, OutputEncoding::Radiance, {0.6f, 0.6f, 0.6f}},
            {"horizon/radiance", InputEncoding::Horizon, OutputEncoding::Radiance, {0.9f, 0.6f, 0.1f}},
            {"seed/phase-factored", InputEncoding::Seed, OutputEncoding::PhaseFactored, {0.2f, 0.5f, 0.9f}},
            {"horizon/phase-factored", InputEncoding::Horizon, OutputEncoding::PhaseFactored, {0.9f, 0.2f, 0.2f}},
        };
        // Large networks cost rows × weights per epoch: fewer epochs, no LM.
        const Size sizes[] = {{"shared:16x12", 60, 20}, {"shared:32x24", 60, 3}, {"shared:64x64", 30, 0},
                              {"shared:128x128", 10, 0}};
        SkyModelOptions so;
        so.steps = kTrainingTargetSteps;
        so.tables = kTrainingTargetTables;
        Atmosphere atm = atmosphere_preset("earth");
        atm.table_rule = TableRule::Refined;
        const SkyModel model(atm, so);
        std::ofstream csv(out / "neural_size.csv");
        csv << "encoding,kind,topology,floats,mean_relative,p50_relative,mean_psnr_db,min_psnr_db,seconds\n";
        // Per encoding: network and table series of error and PSNR. Sizes are
        // the outer loop, so that every finished size is in the CSV and the
        // charts (redrawn after each) while the larger ones train.
        const std::size_t ne = std::size(encodings);
        std::vector<ChartSeries> err, psnr;
        for (const Encoding& e : encodings) {
            err.push_back({fmt::format("{} network", e.name), e.colour, {}, {}});
            err.push_back({fmt::format("{} table", e.name), e.colour * 0.55f, {}, {}});
        }
        psnr = err;
        NeuralErrorOptions eo;
        eo.samples = 20000;
        for (const Size& s : sizes) {
            for (std::size_t k = 0; k < ne; ++k) {
                const Encoding& e = encodings[k];
                NeuralTrainOptions o;
                o.topology = parse_topology(s.topology);
                o.inputs = e.inputs;
                o.outputs = e.outputs;
                o.samples = quick ? 80000 : 800000;
                o.adam_epochs = quick ? 4 : s.epochs;
                o.lm_iterations = quick ? 1 : s.lm;
                o.progress = false;
                const NeuralSky net = train_neural_sky(model, o);
                const NeuralErrorReport r = measure_neural_sky_error(net, eo);
                const std::size_t floats = net.weights.size();
                const SkyLookupTable table = fit_sky_lookup_table(model, o, floats);
                const NeuralErrorReport t = measure_sky_lookup_table_error(table, eo);
                csv << fmt::format("{},network,{},{},{:.6g},{:.6g},{:.4f},{:.4f},{:.1f}\n", e.name,
                                   net.topology.name(), floats, r.all.mean, r.all.p50, r.mean_view_psnr_db,
                                   r.min_view_psnr_db, net.training.seconds);
                csv << fmt::format("{},table,{}x{}x{}x{},{},{:.6g},{:.6g},{:.4f},{:.4f},0\n", e.name, table.size[0],
                                   table.size[1], table.size[2], table.size[3], table.float_count(), t.all.mean,
                                   t.all.p50, t.mean_view_psnr_db, t.min_view_psnr_db);
                csv.flush();
                std::printf("%-24s %-16s %6zu weights: mean %7.3f%%, views %5.2f / %5.2f dB, %5.1f s | table %6zu "
                            "floats: mean %7.3f%%, views %5.2f / %5.2f dB\n",
                            e.name, net.topology.name().c_str(), floats, 100 * r.all.mean, r.mean_view_psnr_db,
                            r.min_view_psnr_db, net.training.seconds, table.float_count(), 100 * t.all.mean,
                            t.mean_view_psnr_db, t.min_view_psnr_db);
                std::fflush(stdout);
                // The x axis is linear: plot log10 of the weight count.
                const double xn = std::log10(double(floats)), xt = std::log10(double(table.float_count()));
                err[2 * k].x.push_back(xn);
                err[2 * k].y.push_back(100 * r.all.mean);
                err[2 * k + 1].x.push_back(xt);
                err[2 * k + 1].y.push_back(100 * t.all.mean);
                psnr[2 * k].x.push_back(xn);
                psnr[2 * k].y.push_back(r.mean_view_psnr_db);
                psnr[2 * k + 1].x.push_back(xt);
                psnr[2 * k + 1].y.push_back(t.mean_view_psnr_db);
            }
            save_image(out / "neural_size_error.png",
                       draw_line_chart(err, "earth: mean relative error against size (networks bright, tables dark)",
                                       "log10 weights (floats)", "mean relative error, %", 900, 560),
                       ToneMap{0.0f, ToneCurve::Clamp});
            save_image(out / "neural_size_psnr.png",
                       draw_line_chart(psnr, "earth: mean view PSNR against size (networks bright, tables dark)",
                                       "log10 weights (floats)", "view PSNR, dB", 900, 560),
                       ToneMap{0.0f, ToneCurve::Clamp});
        }
    } catch (const Error& e) {
        std::fprintf(stderr, "neural_size_report: %s\n", e.what());
        return 1;
    }
    return 0;
}
