// Sky samples from CSV text: the format `skybake sky eval` reads.
#include <sstream>
#include <string_view>

#include <fmt/format.h>

#include "core/parse_number.h"
#include "skybake/error.h"
#include "skybake/sky.h"

namespace skybake {

namespace {

std::string trim(std::string_view s) {
    std::size_t a = 0, b = s.size();
    while (a < b && (s[a] == ' ' || s[a] == '\t' || s[a] == '\r'))
        ++a;
    while (b > a && (s[b - 1] == ' ' || s[b - 1] == '\t' || s[b - 1] == '\r'))
        --b;
    return std::string(s.substr(a, b - a));
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

} // namespace

std::vector<SkySample> read_sky_samples_csv(std::string_view text, const std::string& name) {
    std::vector<SkySample> out;
    std::istringstream in{std::string(text)};
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
        if (first_content && !parse_decimal(fields[0], dummy)) { // a header: columns by name
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
            if (!parse_decimal(fields[std::size_t(column[k])], v[k]))
                throw Error(fmt::format("{} '{}' is not a number", kColumns[k], fields[std::size_t(column[k])]), where);
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

} // namespace skybake
