// Error messages for unknown enum names (skybake/names.h).
#include "skybake/names.h"

#include <fmt/format.h>

#include "skybake/error.h"

namespace skybake {

std::string list_choices(std::span<const std::string_view> names, std::span<const char* const> help) {
    std::string out;
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (i > 0)
            out += i + 1 == names.size() ? " or " : ", ";
        out += names[i];
        if (i < help.size() && help[i] && *help[i])
            out += fmt::format(" ({})", help[i]);
    }
    return out;
}

void throw_unknown_name(std::string_view what, std::string_view text, std::string_view choices,
                        std::string_view where) {
    throw Error(fmt::format("unknown {} '{}'; choose {}", what, text, choices), std::string(where));
}

} // namespace skybake
