// The visibility bits file: seed 002's bit-packed per-vertex visibility
// (layout in skybake/visibility.h, file format in skybake/bake.h).
#include <cstring>
#include <ostream>

#include <fmt/format.h>

#include "skybake/bake.h"
#include "skybake/error.h"
#include "skybake/files.h"

namespace skybake {

namespace {

constexpr char kMagic[8] = {'S', 'K', 'B', 'V', 'I', 'S', '0', '1'};
constexpr std::size_t kHeaderBytes = 8 + 4 * 4;

void put_u32(std::ostream& out, std::uint32_t x) {
    const unsigned char b[4] = {static_cast<unsigned char>(x), static_cast<unsigned char>(x >> 8),
                                static_cast<unsigned char>(x >> 16), static_cast<unsigned char>(x >> 24)};
    out.write(reinterpret_cast<const char*>(b), 4);
}

std::uint32_t get_u32(const std::string& data, std::size_t at) {
    const auto* b = reinterpret_cast<const unsigned char*>(data.data() + at);
    return std::uint32_t(b[0]) | (std::uint32_t(b[1]) << 8) | (std::uint32_t(b[2]) << 16) | (std::uint32_t(b[3]) << 24);
}

} // namespace

void save_visibility_bits(const std::filesystem::path& path, const BakeOutputs& o, const SphereRule& rule) {
    const std::size_t vertices = o.ao.size();
    if (o.directions != rule.size() || o.words_per_vertex != (o.directions + 31) / 32)
        throw Error("the bake outputs do not belong to this rule", path.string());
    if (o.visibility_bits.size() != vertices * o.words_per_vertex)
        throw Error("the bake kept no visibility bits; bake with store_bits", path.string());
    write_stream_atomic(path, [&](std::ostream& out) {
        out.write(kMagic, sizeof kMagic);
        put_u32(out, std::uint32_t(vertices));
        put_u32(out, o.directions);
        put_u32(out, o.words_per_vertex);
        put_u32(out, std::uint32_t(rule.spec.size()));
        out.write(rule.spec.data(), std::streamsize(rule.spec.size()));
        std::string buf;
        buf.reserve(1 << 16);
        for (std::size_t i = 0; i < o.visibility_bits.size(); ++i) {
            const std::uint32_t w = o.visibility_bits[i];
            const char b[4] = {char(w & 0xff), char((w >> 8) & 0xff), char((w >> 16) & 0xff), char(w >> 24)};
            buf.append(b, 4);
            if (buf.size() >= (1 << 16)) {
                out.write(buf.data(), std::streamsize(buf.size()));
                buf.clear();
            }
        }
        out.write(buf.data(), std::streamsize(buf.size()));
    });
}

VisibilityBits load_visibility_bits(const std::filesystem::path& path) {
    const std::string where = path.string();
    const std::string data = read_file(path);
    if (data.size() < kHeaderBytes || std::memcmp(data.data(), kMagic, sizeof kMagic) != 0)
        throw Error("not a skybake visibility bits file (bad magic)", where);
    VisibilityBits r;
    r.vertices = get_u32(data, 8);
    r.directions = get_u32(data, 12);
    r.words_per_vertex = get_u32(data, 16);
    const std::uint32_t spec_len = get_u32(data, 20);
    if (r.words_per_vertex != (std::uint64_t(r.directions) + 31) / 32)
        throw Error(fmt::format("{} words per vertex does not match {} directions", r.words_per_vertex, r.directions),
                    where);
    const std::uint64_t expected =
        kHeaderBytes + std::uint64_t(spec_len) + 4ull * std::uint64_t(r.vertices) * r.words_per_vertex;
    if (data.size() != expected)
        throw Error(fmt::format("file has {} bytes; its header announces {}", data.size(), expected), where);
    r.rule = data.substr(kHeaderBytes, spec_len);
    const std::size_t n = std::size_t(r.vertices) * r.words_per_vertex;
    r.words.resize(n);
    for (std::size_t i = 0; i < n; ++i)
        r.words[i] = get_u32(data, kHeaderBytes + spec_len + 4 * i);
    return r;
}

} // namespace skybake
