// Learning curves: CSV files and a small line-chart rasteriser (log-scale y
// axis, ticks, legend, a built-in 5x7 bitmap font) for the error-against-epoch
// charts of Pietras & Rudnicki (seed 000, section VII: 800,000 against
// 8,000,000 samples).
#include <algorithm>
#include <cctype>
#include <cmath>

#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/files.h"
#include "skybake/neural.h"
#include "skybake/image_io.h"

namespace skybake {

void save_learning_curve_csv(const std::filesystem::path& path, const std::vector<LearningCurvePoint>& curve) {
    write_stream_atomic(path, [&](std::ostream& f) {
        f << "epoch,phase,train_rms,heldout_rms,heldout_mean_relative,seconds\n";
        for (const LearningCurvePoint& p : curve)
            f << fmt::format("{},{},{:.6g},{:.6g},{:.6g},{:.3f}\n", p.epoch, p.phase, p.train_rms, p.heldout_rms,
                             p.heldout_mean_relative, p.seconds);
    });
}

namespace {

// 5x7 glyphs, one string of 35 characters per glyph, rows top to bottom.
struct Glyph {
    char c;
    const char* rows;
};

constexpr Glyph kFont[] = {
    {'0', " ### #   ##  ### # ###  ##   # ### "}, {'1', "  #   ##    #    #    #    #   ### "},
    {'2', " ### #   #    #   #   #   #   #####"}, {'3', "#####   #   #     #     ##   # ### "},
    {'4', "   #   ##  # # #  # #####   #    # "}, {'5', "######    ####     #    ##   # ### "},
    {'6', "  ##  #   #    #### #   ##   # ### "}, {'7', "#####    #   #   #   #    #    #   "},
    {'8', " ### #   ##   # ### #   ##   # ### "}, {'9', " ### #   ##   # ####    #   #  ##  "},
    {'A', " ### #   ##   #######   ##   ##   #"}, {'B', "#### #   ##   ##### #   ##   ##### "},
    {'C', " ### #   ##    #    #    #   # ### "}, {'D', "#### #   ##   ##   ##   ##   ##### "},
    {'E', "######    #    #### #    #    #####"}, {'F', "######    #    #### #    #    #    "},
    {'G', " ### #   ##    # ####   ##   # ####"}, {'H', "#   ##   ##   #######   ##   ##   #"},
    {'I', " ###   #    #    #    #    #   ### "}, {'J', "  ###   #    #    #    # #  #  ##  "},
    {'K', "#   ##  # # #  ##   # #  #  # #   #"}, {'L', "#    #    #    #    #    #    #####"},
    {'M', "#   ### ### # ## # ##   ##   ##   #"}, {'N', "#   ##   ###  ## # ##  ###   ##   #"},
    {'O', " ### #   ##   ##   ##   ##   # ### "}, {'P', "#### #   ##   ##### #    #    #    "},
    {'Q', " ### #   ##   ##   ## # ##  #  ## #"}, {'R', "#### #   ##   ##### # #  #  # #   #"},
    {'S', " #####    #     ###     #    ##### "}, {'T', "#####  #    #    #    #    #    #  "},
    {'U', "#   ##   ##   ##   ##   ##   # ### "}, {'V', "#   ##   ##   ##   ##   # # #   #  "},
    {'W', "#   ##   ##   ## # ## # ## # # # # "}, {'X', "#   ##   # # #   #   # # #   ##   #"},
    {'Y', "#   ##   # # #   #    #    #    #  "}, {'Z', "#####    #   #   #   #   #    #####"},
    {'.', "                          ##   ##  "}, {'-', "               #####               "},
    {'+', "       #    #  #####  #    #       "}, {',', "                     ##    #   #   "},
    {':', "      ##   ##        ##   ##       "}, {'%', "##   ##  #   #   #   #   #  ##   ##"},
    {'(', "   #   #   #    #    #     #     # "}, {')', " #     #     #    #    #   #   #   "},
    {'/', "         #   #   #   #   #         "}, {'=', "          #####     #####          "},
    {'_', "                              #####"}, {'\'', "  #    #   #                       "},
};

const char* glyph(char c) {
    c = char(std::toupper(static_cast<unsigned char>(c)));
    for (const Glyph& g : kFont)
        if (g.c == c)
            return g.rows;
    return nullptr;
}

struct Canvas {
    Image img;
    explicit Canvas(int w, int h) : img(w, h) { std::fill(img.rgb.begin(), img.rgb.end(), 1.0f); }
    void set(int x, int y, const glm::vec3& c) {
        if (x < 0 || y < 0 || x >= img.width || y >= img.height)
            return;
        float* p = img.pixel(x, y);
        p[0] = c.x;
        p[1] = c.y;
        p[2] = c.z;
    }
    void rect(int x0, int y0, int x1, int y1, const glm::vec3& c) {
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                set(x, y, c);
    }
    // A line of the given thickness, by dense stepping along the segment.
    void line(double x0, double y0, double x1, double y1, const glm::vec3& c, int thick = 1, int dash = 0) {
        const double len = std::hypot(x1 - x0, y1 - y0);
        const int n = std::max(1, int(len * 2.0));
        for (int i = 0; i <= n; ++i) {
            if (dash > 0 && (i / (2 * dash)) % 2 == 1)
                continue;
            const double t = double(i) / n;
            const int x = int(std::lround(x0 + (x1 - x0) * t)), y = int(std::lround(y0 + (y1 - y0) * t));
            rect(x - (thick - 1) / 2, y - (thick - 1) / 2, x + thick / 2, y + thick / 2, c);
        }
    }
    static int text_width(const std::string& s, int scale) { return int(s.size()) * 6 * scale - scale; }
    void text(int x, int y, const std::string& s, const glm::vec3& c, int scale = 2) {
        for (char ch : s) {
            if (const char* g = glyph(ch))
                for (int r = 0; r < 7; ++r)
                    for (int k = 0; k < 5; ++k)
                        if (g[r * 5 + k] == '#')
                            rect(x + k * scale, y + r * scale, x + k * scale + scale - 1, y + r * scale + scale - 1, c);
            x += 6 * scale;
        }
    }
};

// A "nice" tick step (1, 2 or 5 times a power of ten) for about `ticks` ticks.
double nice_step(double range, int ticks) {
    const double raw = range / std::max(1, ticks);
    const double p = std::pow(10.0, std::floor(std::log10(raw)));
    const double f = raw / p;
    return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * p;
}

} // namespace

Image draw_line_chart(const std::vector<ChartSeries>& series, const std::string& title, const std::string& x_label,
                      const std::string& y_label, int width, int height) {
    Canvas cv(width, height);
    const glm::vec3 black(0.0f), grid(0.75f), minor(0.9f);
    const int left = 90, right = 20, top = 56, bottom = 56;
    const int pw = width - left - right, ph = height - top - bottom;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (const ChartSeries& s : series)
        for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
            if (!(s.y[i] > 0.0) || !std::isfinite(s.y[i]))
                continue;
            xmin = std::min(xmin, s.x[i]);
            xmax = std::max(xmax, s.x[i]);
            ymin = std::min(ymin, s.y[i]);
            ymax = std::max(ymax, s.y[i]);
        }
    if (!std::isfinite(xmin)) {
        xmin = 0.0, xmax = 1.0, ymin = 0.1, ymax = 1.0;
    }
    // From 0 when the data start near it (epochs); else from the data (log sizes).
    if (xmin < 0.25 * (xmax - xmin))
        xmin = std::min(xmin, 0.0);
    if (xmax <= xmin)
        xmax = xmin + 1.0;
    const double lo = std::floor(std::log10(ymin)), hi = std::max(lo + 1.0, std::ceil(std::log10(ymax)));
    auto px = [&](double x) { return left + (x - xmin) / (xmax - xmin) * pw; };
    auto py = [&](double y) { return top + ph - (std::log10(y) - lo) / (hi - lo) * ph; };

    // Grid and y ticks: decades with labels, 2..9 as minor lines.
    for (int d = int(lo); d <= int(hi); ++d) {
        const double y = py(std::pow(10.0, d));
        cv.line(left, y, left + pw, y, grid);
        const std::string lab = fmt::format("1E{}", d);
        cv.text(left - 8 - Canvas::text_width(lab, 2), int(y) - 7, lab, black);
        if (d < int(hi))
            for (int k = 2; k <= 9; ++k) {
                const double ym = py(k * std::pow(10.0, d));
                cv.line(left, ym, left + pw, ym, minor);
                cv.line(left - 4, ym, left, ym, black);
            }
    }
    const double step = nice_step(xmax - xmin, 8);
    for (double x = std::ceil(xmin / step) * step; x <= xmax + 1e-9 * step; x += step) {
        const double X = px(x);
        cv.line(X, top, X, top + ph, minor);
        cv.line(X, top + ph, X, top + ph + 5, black);
        const std::string lab = fmt::format("{:g}", x);
        cv.text(int(X) - Canvas::text_width(lab, 2) / 2, top + ph + 10, lab, black);
    }
    cv.line(left, top, left, top + ph, black, 2);
    cv.line(left, top + ph, left + pw, top + ph, black, 2);

    for (const ChartSeries& s : series) {
        bool have = false;
        double x0 = 0, y0 = 0;
        for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
            if (!(s.y[i] > 0.0) || !std::isfinite(s.y[i])) {
                have = false;
                continue;
            }
            const double x1 = px(s.x[i]), y1 = py(s.y[i]);
            if (have)
                cv.line(x0, y0, x1, y1, s.colour, 3);
            else
                cv.rect(int(x1) - 1, int(y1) - 1, int(x1) + 1, int(y1) + 1, s.colour);
            x0 = x1, y0 = y1, have = true;
        }
    }
    // Legend, top right inside the plot.
    int ly = top + 10;
    int lw = 0;
    for (const ChartSeries& s : series)
        lw = std::max(lw, Canvas::text_width(s.label, 2));
    const int lx = left + pw - lw - 60;
    cv.rect(lx - 8, ly - 6, left + pw - 6, ly + int(series.size()) * 22 - 4, glm::vec3(1.0f));
    for (const ChartSeries& s : series) {
        cv.line(lx, ly + 7, lx + 36, ly + 7, s.colour, 3);
        cv.text(lx + 44, ly, s.label, black);
        ly += 22;
    }
    cv.text(left, 14, title, black);
    cv.text(left, top - 22, y_label, black);
    cv.text(left + pw / 2 - Canvas::text_width(x_label, 2) / 2, height - 22, x_label, black);
    return std::move(cv.img);
}

void save_learning_curve_png(const std::filesystem::path& path, const std::vector<LearningCurvePoint>& curve,
                             const std::string& title) {
    ChartSeries train{"training", glm::vec3(0.05f, 0.25f, 0.85f), {}, {}};
    ChartSeries held{"held-out", glm::vec3(0.9f, 0.35f, 0.02f), {}, {}};
    for (const LearningCurvePoint& p : curve) {
        train.x.push_back(p.epoch);
        train.y.push_back(p.train_rms);
        held.x.push_back(p.epoch);
        held.y.push_back(p.heldout_rms);
    }
    Image img = draw_line_chart({train, held}, title, "epoch (Adam, then LM iterations)", "RMS error of the outputs");
    ToneMap tm;
    tm.curve = ToneCurve::Clamp;
    save_png(path, img, tm);
}

} // namespace skybake
