// Strict number parsing for text that users write (flag values, CSV fields).
#pragma once

#include <charconv>
#include <string_view>

namespace skybake {

// The whole of `text` as a decimal number (an optional leading '+', no
// spaces, no trailing characters). False for an empty text, for anything
// else, and for values out of double's range (1e400); "nan" and "inf" parse,
// so callers that need a finite number check for it.
inline bool parse_decimal(std::string_view text, double& out) {
    if (text.empty())
        return false;
    const char* first = text.data();
    const char* last = text.data() + text.size();
    if (*first == '+')
        ++first;
    const auto r = std::from_chars(first, last, out);
    return r.ec == std::errc() && r.ptr == last;
}

} // namespace skybake
