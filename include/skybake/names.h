// skybake/names.h: one table per named enum, and the two lookups every enum
// with a name uses: value → name, and name → value with an error that lists
// the choices.
//
//   inline constexpr NamedValue<BackFaces> kBackFacesNames[] = {
//       {BackFaces::Occlude, "occlude", "both sides block rays"},
//       {BackFaces::Ignore, "ignore", "rays pass through triangles they meet from behind"},
//   };
//   name_of(kBackFacesNames, BackFaces::Ignore)                    // "ignore"
//   parse_name(kBackFacesNames, "cull", "back-face mode", "back_faces")
//     // throws Error("unknown back-face mode 'cull'; choose occlude (both sides
//     //               block rays) or ignore (rays pass ...)", "back_faces")
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace skybake {

template <class E>
struct NamedValue {
    E value;
    const char* name;
    const char* help = nullptr;  // a few words for error messages and --help; may be null
    const char* former = nullptr; // an older name still accepted by parse_name(); may be null
};

// "a (help), b or c (help)": the choices as an error message lists them.
std::string list_choices(std::span<const std::string_view> names, std::span<const char* const> help);

// The name of `value`, or "unknown" when the table lacks it.
template <class E, std::size_t N>
const char* name_of(const NamedValue<E> (&table)[N], E value) {
    for (const NamedValue<E>& e : table)
        if (e.value == value)
            return e.name;
    return "unknown";
}

// Throws skybake::Error("unknown <what> '<text>'; choose ...", where).
[[noreturn]] void throw_unknown_name(std::string_view what, std::string_view text, std::string_view choices,
                                     std::string_view where);

// The value named `text`; throws skybake::Error naming `what` (for the message)
// and `where` (the API field) otherwise.
template <class E, std::size_t N>
E parse_name(const NamedValue<E> (&table)[N], std::string_view text, std::string_view what, std::string_view where) {
    for (const NamedValue<E>& e : table)
        if (text == e.name || (e.former && text == e.former))
            return e.value;
    std::vector<std::string_view> names;
    std::vector<const char*> help;
    for (const NamedValue<E>& e : table) {
        names.push_back(e.name);
        help.push_back(e.help);
    }
    throw_unknown_name(what, text, list_choices(names, help), where);
}

// The names in table order.
template <class E, std::size_t N>
std::vector<std::string> names_of(const NamedValue<E> (&table)[N]) {
    std::vector<std::string> out;
    for (const NamedValue<E>& e : table)
        out.emplace_back(e.name);
    return out;
}

} // namespace skybake
