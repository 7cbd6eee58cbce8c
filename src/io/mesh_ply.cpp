// PLY import and export.
// G. Turk, "The PLY Polygon File Format", Stanford, 1994.
//
// skybake reads PLY itself because Assimp drops named vertex properties such
// as "ao", which skybake writes and must read back bit-exactly. The reader is
// defensive: every count in the header is checked against the bytes that
// remain before anything is allocated.
#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>

#include <fmt/format.h>

#include "io/mesh_internal.h"
#include "skybake/error.h"

namespace skybake::io {

namespace {

enum class PlyType { I8, U8, I16, U16, I32, U32, F32, F64, Invalid };

PlyType parse_type(std::string_view s) {
    if (s == "char" || s == "int8") return PlyType::I8;
    if (s == "uchar" || s == "uint8") return PlyType::U8;
    if (s == "short" || s == "int16") return PlyType::I16;
    if (s == "ushort" || s == "uint16") return PlyType::U16;
    if (s == "int" || s == "int32") return PlyType::I32;
    if (s == "uint" || s == "uint32") return PlyType::U32;
    if (s == "float" || s == "float32") return PlyType::F32;
    if (s == "double" || s == "float64") return PlyType::F64;
    return PlyType::Invalid;
}

std::size_t type_size(PlyType t) {
    switch (t) {
    case PlyType::I8: case PlyType::U8: return 1;
    case PlyType::I16: case PlyType::U16: return 2;
    case PlyType::I32: case PlyType::U32: case PlyType::F32: return 4;
    case PlyType::F64: return 8;
    default: return 0;
    }
}

struct Property {
    std::string name;
    PlyType type = PlyType::Invalid;
    bool is_list = false;
    PlyType count_type = PlyType::Invalid;
};

struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> properties;
};

enum class Encoding { Ascii, BinaryLE, BinaryBE };

std::vector<std::string_view> split(std::string_view line) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r'))
            ++i;
        std::size_t j = i;
        while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r')
            ++j;
        if (j > i)
            out.push_back(line.substr(i, j - i));
        i = j;
    }
    return out;
}

// A cursor over the body of the file that yields numbers in either encoding.
class Body {
public:
    Body(const char* begin, const char* end, Encoding enc, const std::string& where)
        : p_(begin), end_(end), enc_(enc), where_(where) {}

    double number(PlyType t) {
        if (enc_ == Encoding::Ascii)
            return ascii_number();
        const std::size_t n = type_size(t);
        if (std::size_t(end_ - p_) < n)
            throw Error("file ends in the middle of the data", where_);
        unsigned char b[8];
        std::memcpy(b, p_, n);
        p_ += n;
        const bool swap = (enc_ == Encoding::BinaryBE) == (std::endian::native == std::endian::little);
        if (swap)
            for (std::size_t i = 0; i < n / 2; ++i)
                std::swap(b[i], b[n - 1 - i]);
        switch (t) {
        case PlyType::I8: return double(std::int8_t(b[0]));
        case PlyType::U8: return double(b[0]);
        case PlyType::I16: { std::int16_t v; std::memcpy(&v, b, 2); return v; }
        case PlyType::U16: { std::uint16_t v; std::memcpy(&v, b, 2); return v; }
        case PlyType::I32: { std::int32_t v; std::memcpy(&v, b, 4); return v; }
        case PlyType::U32: { std::uint32_t v; std::memcpy(&v, b, 4); return v; }
        case PlyType::F32: { float v; std::memcpy(&v, b, 4); return v; }
        case PlyType::F64: { double v; std::memcpy(&v, b, 8); return v; }
        default: return 0.0;
        }
    }

    // A float read without going through double, so values round-trip bit-exactly.
    float number_f32(PlyType t) {
        if (enc_ == Encoding::Ascii) {
            skip_space();
            float v = 0.0f;
            const auto r = std::from_chars(p_, end_, v);
            if (r.ec == std::errc::invalid_argument)
                throw Error(fmt::format("expected a number, found '{}'", token_preview()), where_);
            p_ = r.ptr;
            return v;
        }
        return float(number(t));
    }

    std::size_t remaining() const { return std::size_t(end_ - p_); }

private:
    void skip_space() {
        while (p_ < end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\r' || *p_ == '\n'))
            ++p_;
        if (p_ == end_)
            throw Error("file ends in the middle of the data", where_);
    }
    std::string token_preview() const {
        const char* q = p_;
        while (q < end_ && q - p_ < 20 && *q != ' ' && *q != '\n')
            ++q;
        return std::string(p_, q);
    }
    double ascii_number() {
        skip_space();
        double v = 0.0;
        const auto r = std::from_chars(p_, end_, v);
        if (r.ec == std::errc::invalid_argument)
            throw Error(fmt::format("expected a number, found '{}'", token_preview()), where_);
        p_ = r.ptr; // out-of-range values saturate; validation catches non-finite results
        if (r.ec == std::errc::result_out_of_range)
            v = HUGE_VAL;
        return v;
    }

    const char* p_;
    const char* end_;
    Encoding enc_;
    const std::string& where_;
};

} // namespace

RawImport read_ply(const void* data, std::size_t size, const std::string& where, const ImportLimits& limits) {
    const char* begin = static_cast<const char*>(data);
    const char* end = begin + size;
    // --- header
    const std::string_view all(begin, size);
    const std::size_t header_limit = std::min<std::size_t>(size, 1 << 20);
    std::size_t pos = 0;
    auto next_line = [&]() -> std::string_view {
        const std::size_t nl = all.find('\n', pos);
        if (nl == std::string_view::npos || nl >= header_limit)
            throw Error("PLY header has no end_header line", where);
        std::string_view line = all.substr(pos, nl - pos);
        pos = nl + 1;
        return line;
    };
    if (split(next_line()) != std::vector<std::string_view>{"ply"})
        throw Error("not a PLY file (no 'ply' magic line)", where);
    Encoding enc = Encoding::Ascii;
    bool have_format = false;
    std::vector<Element> elements;
    for (;;) {
        const auto tok = split(next_line());
        if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info")
            continue;
        if (tok[0] == "end_header")
            break;
        if (tok[0] == "format") {
            if (tok.size() != 3 || tok[2] != "1.0")
                throw Error("bad PLY format line", where);
            if (tok[1] == "ascii") enc = Encoding::Ascii;
            else if (tok[1] == "binary_little_endian") enc = Encoding::BinaryLE;
            else if (tok[1] == "binary_big_endian") enc = Encoding::BinaryBE;
            else throw Error(fmt::format("unknown PLY encoding '{}'", tok[1]), where);
            have_format = true;
        } else if (tok[0] == "element") {
            if (tok.size() != 3)
                throw Error("bad PLY element line", where);
            Element e;
            e.name = tok[1];
            const auto r = std::from_chars(tok[2].data(), tok[2].data() + tok[2].size(), e.count);
            if (r.ec != std::errc() || r.ptr != tok[2].data() + tok[2].size())
                throw Error(fmt::format("bad count '{}' for PLY element '{}'", tok[2], tok[1]), where);
            elements.push_back(std::move(e));
        } else if (tok[0] == "property") {
            if (elements.empty())
                throw Error("PLY property before any element", where);
            Property p;
            if (tok.size() == 5 && tok[1] == "list") {
                p.is_list = true;
                p.count_type = parse_type(tok[2]);
                p.type = parse_type(tok[3]);
                p.name = tok[4];
                if (p.count_type == PlyType::Invalid || p.count_type == PlyType::F32 || p.count_type == PlyType::F64)
                    throw Error(fmt::format("bad list count type '{}'", tok[2]), where);
            } else if (tok.size() == 3) {
                p.type = parse_type(tok[1]);
                p.name = tok[2];
            } else {
                throw Error("bad PLY property line", where);
            }
            if (p.type == PlyType::Invalid)
                throw Error(fmt::format("unknown PLY property type in '{}'", p.name), where);
            elements.back().properties.push_back(std::move(p));
        }
        // Other lines are not in the format; some writers put free text there
        // (Blender 2.4: "Created by Blender3D"). They are ignored.
    }
    if (!have_format)
        throw Error("PLY header has no format line", where);

    // --- sanity of counts against the bytes left, before allocating anything
    const std::size_t body_bytes = size - pos;
    for (const Element& e : elements) {
        std::size_t min_bytes = 0;
        for (const Property& p : e.properties)
            min_bytes += enc == Encoding::Ascii ? 2 : (p.is_list ? type_size(p.count_type) : type_size(p.type));
        if (min_bytes > 0 && e.count > body_bytes / min_bytes)
            throw Error(fmt::format("PLY element '{}' declares {} entries, more than the file can hold", e.name,
                                    e.count),
                        where);
    }

    RawImport out;
    out.report.format = "ply";
    out.report.source_meshes = 1;
    Mesh& mesh = out.mesh;
    Body body(begin + pos, end, enc, where);
    bool have_vertices = false;
    for (const Element& e : elements) {
        if (e.name == "vertex" && !have_vertices) {
            have_vertices = true;
            check_counts(e.count, 0, limits, where);
            // Map properties to destinations.
            enum Kind { Skip, Pos, Nrm, Col, Attr, Uv };
            struct Slot { Kind kind = Skip; int comp = 0; std::size_t attr = 0; };
            std::vector<Slot> slots(e.properties.size());
            bool has_pos[3] = {}, has_nrm[3] = {}, has_col = false, has_uv[2] = {};
            bool col_float = false;
            for (std::size_t i = 0; i < e.properties.size(); ++i) {
                const Property& p = e.properties[i];
                if (p.is_list)
                    continue;
                static const char* pn[] = {"x", "y", "z"};
                static const char* nn[] = {"nx", "ny", "nz"};
                static const char* cn[] = {"red", "green", "blue", "alpha"};
                for (int k = 0; k < 3; ++k) {
                    if (p.name == pn[k]) { slots[i] = {Pos, k}; has_pos[k] = true; }
                    if (p.name == nn[k]) { slots[i] = {Nrm, k}; has_nrm[k] = true; }
                }
                for (int k = 0; k < 4; ++k)
                    if (p.name == cn[k]) {
                        slots[i] = {Col, k};
                        has_col = true;
                        col_float = p.type == PlyType::F32 || p.type == PlyType::F64;
                    }
                // Texture coordinates, as the PLY writers in use name them.
                static const char* un[] = {"s", "u", "texture_u", "texture_s"};
                static const char* vn[] = {"t", "v", "texture_v", "texture_t"};
                for (int k = 0; k < 4; ++k) {
                    if (p.name == un[k] && !has_uv[0]) { slots[i] = {Uv, 0}; has_uv[0] = true; }
                    if (p.name == vn[k] && !has_uv[1]) { slots[i] = {Uv, 1}; has_uv[1] = true; }
                }
                if (slots[i].kind != Skip || !is_valid_attribute_name(p.name))
                    continue;
                // "name_x", "name_y", ... following each other form one attribute.
                std::string base = p.name;
                int comp = -1;
                if (base.size() > 2 && base[base.size() - 2] == '_') {
                    const char c = base.back();
                    comp = c == 'x' ? 0 : c == 'y' ? 1 : c == 'z' ? 2 : c == 'w' ? 3 : -1;
                    if (comp >= 0)
                        base.resize(base.size() - 2);
                }
                if (comp > 0 && !mesh.attributes.empty() && mesh.attributes.back().name == base &&
                    mesh.attributes.back().components == comp) {
                    mesh.attributes.back().components = comp + 1;
                    slots[i] = {Attr, comp, mesh.attributes.size() - 1};
                } else {
                    mesh.attributes.push_back({comp == 0 ? base : p.name, 1, {}});
                    slots[i] = {Attr, 0, mesh.attributes.size() - 1};
                }
            }
            if (!(has_pos[0] && has_pos[1] && has_pos[2]))
                throw Error("PLY vertex element lacks x, y or z", where);
            const bool normals = has_nrm[0] && has_nrm[1] && has_nrm[2];
            if (!normals) // a partial normal (nx without nz) is ignored
                for (Slot& s : slots)
                    if (s.kind == Nrm)
                        s.kind = Skip;
            const bool uvs = has_uv[0] && has_uv[1];
            if (!uvs) // a lone s or u is ignored
                for (Slot& s : slots)
                    if (s.kind == Uv)
                        s.kind = Skip;
            if (uvs)
                mesh.texcoords.assign(1, std::vector<glm::vec2>(e.count, glm::vec2(0.0f)));
            mesh.positions.resize(e.count);
            if (normals)
                mesh.normals.resize(e.count);
            if (has_col)
                mesh.colors.assign(e.count, glm::vec4(1.0f));
            for (auto& a : mesh.attributes)
                a.values.resize(e.count * std::size_t(a.components));
            const float col_scale = col_float ? 1.0f : 1.0f / 255.0f;
            for (std::uint64_t v = 0; v < e.count; ++v) {
                for (std::size_t i = 0; i < e.properties.size(); ++i) {
                    const Property& p = e.properties[i];
                    if (p.is_list) { // unusual; read and ignore
                        const double n = body.number(p.count_type);
                        if (!(n >= 0 && n <= 65536))
                            throw Error("bad list length in vertex element", where);
                        for (int k = 0; k < int(n); ++k)
                            body.number(p.type);
                        continue;
                    }
                    const Slot& s = slots[i];
                    switch (s.kind) {
                    case Pos: mesh.positions[v][s.comp] = body.number_f32(p.type); break;
                    case Nrm: mesh.normals[v][s.comp] = body.number_f32(p.type); break;
                    case Col: mesh.colors[v][s.comp] = float(body.number(p.type)) * col_scale; break;
                    case Uv: { // PLY's t grows upwards, glTF's v downwards
                        const float x = body.number_f32(p.type);
                        mesh.texcoords[0][v][s.comp] = s.comp == 0 ? x : 1.0f - x;
                        break;
                    }
                    case Attr: {
                        auto& a = mesh.attributes[s.attr];
                        a.values[v * std::size_t(a.components) + std::size_t(s.comp)] = body.number_f32(p.type);
                        break;
                    }
                    case Skip: body.number(p.type); break;
                    }
                }
            }
        } else if (e.name == "face" && mesh.indices.empty()) {
            int list = -1;
            for (std::size_t i = 0; i < e.properties.size(); ++i)
                if (e.properties[i].is_list &&
                    (e.properties[i].name == "vertex_indices" || e.properties[i].name == "vertex_index"))
                    list = int(i);
            if (list < 0)
                throw Error("PLY face element has no vertex_indices list", where);
            for (std::uint64_t f = 0; f < e.count; ++f) {
                for (std::size_t i = 0; i < e.properties.size(); ++i) {
                    const Property& p = e.properties[i];
                    if (!p.is_list) {
                        body.number(p.type);
                        continue;
                    }
                    const double nd = body.number(p.count_type);
                    if (!(nd >= 0 && nd <= 65536))
                        throw Error(fmt::format("face {} has a bad vertex count", f), where);
                    const int n = int(nd);
                    if (int(i) != list) {
                        for (int k = 0; k < n; ++k)
                            body.number(p.type);
                        continue;
                    }
                    if (n < 3) {
                        ++out.report.non_triangles;
                        for (int k = 0; k < n; ++k)
                            body.number(p.type);
                        continue;
                    }
                    std::uint32_t first = 0, prev = 0;
                    for (int k = 0; k < n; ++k) {
                        const double idx = body.number(p.type);
                        if (!(idx >= 0 && idx < 4294967295.0))
                            throw Error(fmt::format("face {} has vertex index {}", f, idx), where);
                        const auto u = std::uint32_t(idx);
                        if (k == 0)
                            first = u;
                        else if (k >= 2) { // fan triangulation
                            mesh.indices.push_back(first);
                            mesh.indices.push_back(prev);
                            mesh.indices.push_back(u);
                        }
                        prev = u;
                    }
                    check_counts(0, mesh.triangle_count(), limits, where);
                }
            }
        } else {
            // Other elements (edges, materials, ...): read past them. One with
            // no properties takes no bytes, whatever its count (a count of
            // 4e17 looped for ever: found by the fuzzer).
            if (e.properties.empty())
                continue;
            for (std::uint64_t k = 0; k < e.count; ++k)
                for (const Property& p : e.properties) {
                    if (p.is_list) {
                        const double n = body.number(p.count_type);
                        if (!(n >= 0 && n <= 65536))
                            throw Error(fmt::format("bad list length in element '{}'", e.name), where);
                        for (int j = 0; j < int(n); ++j)
                            body.number(p.type);
                    } else {
                        body.number(p.type);
                    }
                }
        }
    }
    if (!have_vertices)
        throw Error("PLY file has no vertex element", where);
    return out;
}

void write_ply(const std::filesystem::path& tmp, const Mesh& mesh, PlyEncoding encoding) {
    const bool ascii = encoding == PlyEncoding::Ascii;
    const std::size_t n = mesh.vertex_count();
    std::string header = fmt::format("ply\nformat {} 1.0\ncomment written by skybake\nelement vertex {}\n",
                                     ascii ? "ascii" : "binary_little_endian", n);
    header += "property float x\nproperty float y\nproperty float z\n";
    const bool normals = !mesh.normals.empty();
    if (normals)
        header += "property float nx\nproperty float ny\nproperty float nz\n";
    const bool colors = !mesh.colors.empty();
    if (colors)
        header += "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
    const bool uvs = !mesh.texcoords.empty();
    if (uvs) // TEXCOORD_0 only; t grows upwards
        header += "property float s\nproperty float t\n";
    static const char* suffix[] = {"_x", "_y", "_z", "_w"};
    for (const auto& a : mesh.attributes) {
        if (a.components == 1)
            header += fmt::format("property float {}\n", a.name);
        else
            for (int k = 0; k < a.components; ++k)
                header += fmt::format("property float {}{}\n", a.name, suffix[k]);
    }
    header += fmt::format("element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
                          mesh.triangle_count());

    std::ofstream out(tmp, std::ios::binary);
    if (!out)
        throw Error("cannot create file", tmp.string());
    out << header;
    auto u8 = [](float c) { return std::uint8_t(std::lround(std::clamp(c, 0.0f, 1.0f) * 255.0f)); };
    std::string buf;
    buf.reserve(1 << 16);
    auto flush = [&](bool force) {
        if (force || buf.size() > (1 << 15)) {
            out.write(buf.data(), std::streamsize(buf.size()));
            buf.clear();
        }
    };
    auto put_f = [&](float f) {
        if (ascii) {
            fmt::format_to(std::back_inserter(buf), "{} ", f); // shortest round-trip form
        } else {
            char b[4];
            std::memcpy(b, &f, 4);
            if constexpr (std::endian::native == std::endian::big)
                std::reverse(b, b + 4);
            buf.append(b, 4);
        }
    };
    auto put_u8 = [&](std::uint8_t v) {
        if (ascii)
            fmt::format_to(std::back_inserter(buf), "{} ", v);
        else
            buf.push_back(char(v));
    };
    auto put_u32 = [&](std::uint32_t v) {
        if (ascii) {
            fmt::format_to(std::back_inserter(buf), "{} ", v);
        } else {
            char b[4];
            std::memcpy(b, &v, 4);
            if constexpr (std::endian::native == std::endian::big)
                std::reverse(b, b + 4);
            buf.append(b, 4);
        }
    };
    auto end_row = [&] {
        if (ascii) {
            buf.back() = '\n';
        }
        flush(false);
    };
    for (std::size_t v = 0; v < n; ++v) {
        for (int k = 0; k < 3; ++k)
            put_f(mesh.positions[v][k]);
        if (normals)
            for (int k = 0; k < 3; ++k)
                put_f(mesh.normals[v][k]);
        if (colors)
            for (int k = 0; k < 4; ++k)
                put_u8(u8(mesh.colors[v][k]));
        if (uvs) {
            put_f(mesh.texcoords[0][v].x);
            put_f(1.0f - mesh.texcoords[0][v].y);
        }
        for (const auto& a : mesh.attributes)
            for (int k = 0; k < a.components; ++k)
                put_f(a.values[v * std::size_t(a.components) + std::size_t(k)]);
        end_row();
    }
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        put_u8(3);
        for (int k = 0; k < 3; ++k)
            put_u32(mesh.indices[t * 3 + std::size_t(k)]);
        end_row();
    }
    flush(true);
    if (!out.flush())
        throw Error("write failed (disk full?)", tmp.string());
}

} // namespace skybake::io
