// The size–accuracy curve of docs/neural.md: for every encoding, networks of
// about 300 to 20,000 weights trained on `earth`, and beside each a plain 4D
// look-up table of the same number of floats over the same inputs
// (SkyLookupTable), all measured by measure_neural_sky_error's views and
// 20,000 of its held-out samples. An accuracy measurement, not a timing.
//
//   neural_size_report OUT_DIR [--quick] [--tables-only]
//
// Writes OUT_DIR/neural_size.csv and the charts neural_size_error.png and
// neural_size_psnr.png, drawn from the CSV after every row. After the
// networks come tables alone at a size no network here is trained at (64K
// floats), to show how far a table of more memory gets.
// --tables-only appends just those to an existing CSV, --charts-only redraws
// the charts from it; --quick trains a tenth of the samples (a smoke run).
#include <algorithm>
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
#include "skybake/image_io.h"
#include "neural/internal.h"

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
    double learning_rate; // Adam's first step: 0.02 (the default) kills 128-wide networks
};

const Encoding kEncodings[] = {
    {"seed/radiance", InputEncoding::Seed, OutputEncoding::Radiance, {0.6f, 0.6f, 0.6f}},
    {"horizon/radiance", InputEncoding::Horizon, OutputEncoding::Radiance, {0.9f, 0.6f, 0.1f}},
    {"seed/phase-factored", InputEncoding::Seed, OutputEncoding::PhaseFactored, {0.2f, 0.5f, 0.9f}},
    {"horizon/phase-factored", InputEncoding::Horizon, OutputEncoding::PhaseFactored, {0.9f, 0.2f, 0.2f}},
    // No look-up table holds residual outputs (they correct a march per sample).
    {"horizon/residual", InputEncoding::Horizon, OutputEncoding::Residual, {0.2f, 0.8f, 0.3f}},
};
constexpr const char* kHeader =
    "encoding,kind,topology,floats,mean_relative,p50_relative,mean_psnr_db,min_psnr_db,seconds";

// Both charts from every row of the CSV: per encoding a network and a table
// series of mean relative error and mean view PSNR against log10 of the size.
void draw_charts(const std::filesystem::path& out) {
    std::vector<ChartSeries> err, psnr;
    for (const Encoding& e : kEncodings) {
        err.push_back({fmt::format("{} network", e.name), e.colour, {}, {}});
        err.push_back({fmt::format("{} table", e.name), e.colour * 0.55f, {}, {}});
    }
    psnr = err;
    std::ifstream csv(out / "neural_size.csv");
    std::string line;
    std::getline(csv, line);
    while (std::getline(csv, line)) {
        std::vector<std::string> f;
        for (std::size_t b = 0, e; b <= line.size(); b = e + 1) {
            e = std::min(line.find(',', b), line.size());
            f.push_back(line.substr(b, e - b));
        }
        if (f.size() != 9)
            continue;
        for (std::size_t k = 0; k < std::size(kEncodings); ++k) {
            if (f[0] != kEncodings[k].name)
                continue;
            const std::size_t series = 2 * k + (f[1] == "table" ? 1 : 0);
            const double x = std::log10(std::stod(f[3])); // the x axis is linear
            err[series].x.push_back(x);
            err[series].y.push_back(100 * std::stod(f[4]));
            psnr[series].x.push_back(x);
            psnr[series].y.push_back(std::stod(f[6]));
        }
    }
    // Series with no rows (no table holds residual outputs) stay out of the legend.
    for (std::vector<ChartSeries>* v : {&err, &psnr})
        std::erase_if(*v, [](const ChartSeries& s) { return s.x.empty(); });
    save_image(out / "neural_size_error.png",
               draw_line_chart(err, "earth: mean relative error (networks bright, tables dark)",
                               "log10 weights (floats)", "mean relative error, %", 900, 560),
               ToneMap{0.0f, ToneCurve::Clamp});
    save_image(out / "neural_size_psnr.png",
               draw_line_chart(psnr, "earth: mean view PSNR (networks bright, tables dark)",
                               "log10 weights (floats)", "view PSNR, dB", 900, 560),
               ToneMap{0.0f, ToneCurve::Clamp});
}

void table_row(std::ofstream& csv, const Encoding& e, const SkyModel& model, const NeuralTrainOptions& o,
               std::size_t floats, const NeuralErrorOptions& eo) {
    const SkyLookupTable table = fit_sky_lookup_table(model, o, floats);
    const NeuralErrorReport t = measure_sky_lookup_table_error(table, eo);
    csv << fmt::format("{},table,{}x{}x{}x{},{},{:.6g},{:.6g},{:.4f},{:.4f},0\n", e.name, table.size[0],
                       table.size[1], table.size[2], table.size[3], table.float_count(), t.all.mean, t.all.p50,
                       t.mean_view_psnr_db, t.min_view_psnr_db);
    csv.flush();
    std::printf("%-24s table %6zu floats (%dx%dx%dx%d): mean %7.3f%%, views %5.2f / %5.2f dB\n", e.name,
                table.float_count(), table.size[0], table.size[1], table.size[2], table.size[3], 100 * t.all.mean,
                t.mean_view_psnr_db, t.min_view_psnr_db);
    std::fflush(stdout);
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: neural_size_report OUT_DIR [--quick] [--tables-only | --charts-only | "
                             "--encoding NAME]\n");
        return 2;
    }
    const std::filesystem::path out = argv[1];
    bool quick = false, tables_only = false, charts_only = false;
    std::string only; // --encoding: that encoding's networks, appended to the CSV
    for (int i = 2; i < argc; ++i) {
        if (std::strcmp(argv[i], "--quick") == 0)
            quick = true;
        else if (std::strcmp(argv[i], "--encoding") == 0 && i + 1 < argc)
            only = argv[++i];
        else if (std::strcmp(argv[i], "--tables-only") == 0)
            tables_only = true;
        else if (std::strcmp(argv[i], "--charts-only") == 0)
            charts_only = true;
        else {
            std::fprintf(stderr, "neural_size_report: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    try {
        if (charts_only) {
            draw_charts(out);
            return 0;
        }
        std::filesystem::create_directories(out);
        // Large networks cost rows × weights per epoch: fewer epochs, no LM,
        // and a smaller first step (at 0.02 a 128-wide network ends at 100%
        // error, at 0.005 at 17%, after 10 epochs).
        const Size sizes[] = {{"shared:16x12", 60, 20, 0.02}, {"shared:32x24", 60, 3, 0.02},
                              {"shared:64x64", 60, 0, 0.01}, {"shared:128x128", 30, 0, 0.005}};
        // 256K floats (16⁴ nodes) took over ten minutes to factor on two cores:
        // the sparse Cholesky of a 4D grid fills in.
        const std::size_t large_tables[] = {65536};
        SkyModelOptions so;
        so.steps = kTrainingTargetSteps;
        so.tables = kTrainingTargetTables;
        Atmosphere atm = atmosphere_preset("earth");
        atm.table_rule = TableRule::Refined;
        const SkyModel model(atm, so);
        const std::filesystem::path csv_path = out / "neural_size.csv";
        const bool fresh = (!tables_only && only.empty()) || !std::filesystem::exists(csv_path);
        std::ofstream csv(csv_path, fresh ? std::ios::trunc : std::ios::app);
        if (fresh)
            csv << kHeader << "\n";
        NeuralErrorOptions eo;
        eo.samples = 20000;
        auto options = [&](const Encoding& e) {
            NeuralTrainOptions o;
            o.inputs = e.inputs;
            o.outputs = e.outputs;
            o.samples = quick ? 80000 : 800000;
            o.progress = false;
            return o;
        };
        // Sizes are the outer loop, so that every finished size is in the CSV
        // and the charts while the larger ones train.
        for (const Size& s : sizes) {
            if (tables_only)
                break;
            for (const Encoding& e : kEncodings) {
                if (!only.empty() && only != e.name)
                    continue;
                NeuralTrainOptions o = options(e);
                o.topology = parse_topology(s.topology);
                o.adam_epochs = quick ? 4 : s.epochs;
                o.lm_iterations = quick ? 1 : s.lm;
                o.learning_rate = s.learning_rate;
                const NeuralSky net = train_neural_sky(model, o);
                const NeuralErrorReport r = measure_neural_sky_error(net, eo);
                csv << fmt::format("{},network,{},{},{:.6g},{:.6g},{:.4f},{:.4f},{:.1f}\n", e.name,
                                   net.topology.name(), net.weights.size(), r.all.mean, r.all.p50,
                                   r.mean_view_psnr_db, r.min_view_psnr_db, net.training.seconds);
                std::printf("%-24s %-16s %6zu weights: mean %7.3f%% (twilight %.2f%%, flight %.2f%%, flight twilight "
                            "%.2f%%), views %5.2f / %5.2f dB, %5.1f s\n",
                            e.name, net.topology.name().c_str(), net.weights.size(), 100 * r.all.mean,
                            100 * r.twilight.mean, 100 * r.flight_all.mean, 100 * r.flight_twilight.mean,
                            r.mean_view_psnr_db, r.min_view_psnr_db, net.training.seconds);
                std::fflush(stdout);
                if (e.outputs != OutputEncoding::Residual)
                    table_row(csv, e, model, o, net.weights.size(), eo);
            }
            draw_charts(out);
        }
        // Tables beyond the networks' sizes, fitted to enough samples that
        // every node is seen (about 24 per node).
        for (std::size_t floats : large_tables) {
            if (!only.empty())
                break;
            for (const Encoding& e : kEncodings) {
                if (e.outputs == OutputEncoding::Residual)
                    continue;
                NeuralTrainOptions o = options(e);
                const std::size_t outputs = std::size_t(neural::make_training_encoding(model, o).output_count());
                o.samples = std::max(o.samples, 24 * (quick ? floats / 10 : floats) / outputs);
                table_row(csv, e, model, o, quick ? floats / 10 : floats, eo);
            }
            draw_charts(out);
        }
    } catch (const Error& e) {
        std::fprintf(stderr, "neural_size_report: %s\n", e.what());
        return 1;
    }
    return 0;
}
