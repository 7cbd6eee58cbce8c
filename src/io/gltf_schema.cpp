// Structural validation of glTF JSON before it is loaded.
// Khronos Group, "glTF 2.0 Specification", JSON schema, 2017-2021.
//
// tinygltf silently ignores members of the wrong JSON type; a file that says
// "primitives": {} or "scene": "hello" is malformed, and skybake rejects it
// with the path of the first offending member. Only the members that exist in
// the core specification are checked; unknown members are allowed.
#include <cstring>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "io/gltf_schema.h"
#include "skybake/error.h"

namespace skybake::io {

namespace {

using json = nlohmann::json;

enum class T { Uint, Number, Bool, String, Object, Array, UintArray, NumberArray, StringArray, ObjectArray };

const char* type_name(T t) {
    switch (t) {
    case T::Uint: return "a non-negative integer";
    case T::Number: return "a number";
    case T::Bool: return "a boolean";
    case T::String: return "a string";
    case T::Object: return "an object";
    case T::Array: return "an array";
    case T::UintArray: return "an array of non-negative integers";
    case T::NumberArray: return "an array of numbers";
    case T::StringArray: return "an array of strings";
    case T::ObjectArray: return "an array of objects";
    }
    return "?";
}

bool is_uint(const json& j) { return j.is_number_unsigned() || (j.is_number_integer() && j.get<std::int64_t>() >= 0); }

bool matches(const json& j, T t) {
    auto all = [&](auto pred) {
        if (!j.is_array())
            return false;
        for (const auto& e : j)
            if (!pred(e))
                return false;
        return true;
    };
    switch (t) {
    case T::Uint: return is_uint(j);
    case T::Number: return j.is_number();
    case T::Bool: return j.is_boolean();
    case T::String: return j.is_string();
    case T::Object: return j.is_object();
    case T::Array: return j.is_array();
    case T::UintArray: return all(is_uint);
    case T::NumberArray: return all([](const json& e) { return e.is_number(); });
    case T::StringArray: return all([](const json& e) { return e.is_string(); });
    case T::ObjectArray: return all([](const json& e) { return e.is_object(); });
    }
    return false;
}

struct Member {
    const char* name;
    T type;
};

class Validator {
public:
    explicit Validator(const std::string& where) : where_(where) {}

    // Checks the common members of every glTF object, then the listed ones.
    void object(const json& o, const std::string& path, std::initializer_list<Member> members) {
        if (!o.is_object())
            fail(path, "an object");
        check(o, path, "name", T::String);
        if (auto it = o.find("extensions"); it != o.end()) {
            if (!it->is_object())
                fail(path + ".extensions", "an object");
            for (auto e = it->begin(); e != it->end(); ++e)
                if (!e->is_object())
                    fail(path + ".extensions." + e.key(), "an object");
        }
        for (const Member& m : members)
            check(o, path, m.name, m.type);
    }

    bool check(const json& o, const std::string& path, const char* name, T type) {
        auto it = o.find(name);
        if (it == o.end())
            return false;
        if (!matches(*it, type))
            fail(path + "." + name, type_name(type));
        return true;
    }

    template <class F>
    void each(const json& root, const char* name, F f) {
        auto it = root.find(name);
        if (it == root.end())
            return;
        if (!it->is_array())
            fail(name, "an array");
        for (std::size_t i = 0; i < it->size(); ++i)
            f((*it)[i], fmt::format("{}[{}]", name, i));
    }

    void texture_info(const json& parent, const std::string& path, const char* name, std::initializer_list<Member> extra) {
        auto it = parent.find(name);
        if (it == parent.end())
            return;
        object(*it, path + "." + name, {{"index", T::Uint}, {"texCoord", T::Uint}});
        for (const Member& m : extra)
            check(*it, path + "." + name, m.name, m.type);
    }

    [[noreturn]] void fail(const std::string& path, const char* expected) const {
        throw Error(fmt::format("malformed glTF: '{}' must be {}", path, expected), where_);
    }

private:
    const std::string& where_;
};

void validate(const json& root, const std::string& where) {
    Validator v(where);
    if (!root.is_object())
        throw Error("malformed glTF: the top level is not a JSON object", where);
    v.object(root, "glTF", {{"asset", T::Object}, {"scene", T::Uint}, {"extensionsUsed", T::StringArray},
                            {"extensionsRequired", T::StringArray}});
    for (const char* arr : {"accessors", "animations", "buffers", "bufferViews", "cameras", "images", "materials",
                            "meshes", "nodes", "samplers", "scenes", "skins", "textures"})
        v.check(root, "glTF", arr, T::ObjectArray);

    v.each(root, "scenes", [&](const json& o, const std::string& p) { v.object(o, p, {{"nodes", T::UintArray}}); });
    v.each(root, "nodes", [&](const json& o, const std::string& p) {
        v.object(o, p, {{"children", T::UintArray}, {"mesh", T::Uint}, {"camera", T::Uint}, {"skin", T::Uint},
                        {"matrix", T::NumberArray}, {"translation", T::NumberArray}, {"rotation", T::NumberArray},
                        {"scale", T::NumberArray}, {"weights", T::NumberArray}});
        auto size_is = [&](const char* name, std::size_t n) {
            auto it = o.find(name);
            if (it != o.end() && it->size() != n)
                throw Error(fmt::format("malformed glTF: '{}.{}' must have {} numbers", p, name, n), where);
        };
        size_is("matrix", 16);
        size_is("translation", 3);
        size_is("rotation", 4);
        size_is("scale", 3);
    });
    v.each(root, "meshes", [&](const json& o, const std::string& p) {
        v.object(o, p, {{"primitives", T::ObjectArray}, {"weights", T::NumberArray}});
        if (auto it = o.find("primitives"); it != o.end())
            for (std::size_t i = 0; i < it->size(); ++i) {
                const std::string pp = fmt::format("{}.primitives[{}]", p, i);
                v.object((*it)[i], pp, {{"attributes", T::Object}, {"indices", T::Uint}, {"material", T::Uint},
                                        {"mode", T::Uint}, {"targets", T::ObjectArray}});
                if (auto a = (*it)[i].find("attributes"); a != (*it)[i].end())
                    for (auto e = a->begin(); e != a->end(); ++e)
                        if (!is_uint(*e))
                            v.fail(pp + ".attributes." + e.key(), type_name(T::Uint));
            }
    });
    v.each(root, "accessors", [&](const json& o, const std::string& p) {
        v.object(o, p, {{"bufferView", T::Uint}, {"byteOffset", T::Uint}, {"componentType", T::Uint},
                        {"normalized", T::Bool}, {"count", T::Uint}, {"type", T::String}, {"min", T::NumberArray},
                        {"max", T::NumberArray}, {"sparse", T::Object}});
    });
    v.each(root, "bufferViews", [&](const json& o, const std::string& p) {
        v.object(o, p, {{"buffer", T::Uint}, {"byteOffset", T::Uint}, {"byteLength", T::Uint},
                        {"byteStride", T::Uint}, {"target", T::Uint}});
    });
    v.each(root, "buffers", [&](const json& o, const std::string& p) {
        v.object(o, p, {{"uri", T::String}, {"byteLength", T::Uint}});
    });
    v.each(root, "materials", [&](const json& o, const std::string& p) {
        v.object(o, p, {{"pbrMetallicRoughness", T::Object}, {"emissiveFactor", T::NumberArray},
                        {"alphaMode", T::String}, {"alphaCutoff", T::Number}, {"doubleSided", T::Bool}});
        v.texture_info(o, p, "normalTexture", {{"scale", T::Number}});
        v.texture_info(o, p, "occlusionTexture", {{"strength", T::Number}});
        v.texture_info(o, p, "emissiveTexture", {});
        if (auto it = o.find("pbrMetallicRoughness"); it != o.end()) {
            const std::string pp = p + ".pbrMetallicRoughness";
            v.object(*it, pp, {{"baseColorFactor", T::NumberArray}, {"metallicFactor", T::Number},
                               {"roughnessFactor", T::Number}});
            v.texture_info(*it, pp, "baseColorTexture", {});
            v.texture_info(*it, pp, "metallicRoughnessTexture", {});
        }
    });
    v.each(root, "textures", [&](const json& o, const std::string& p) {
        v.object(o, p, {{"sampler", T::Uint}, {"source", T::Uint}});
    });
    v.each(root, "images", [&](const json& o, const std::string& p) {
        v.object(o, p, {{"uri", T::String}, {"mimeType", T::String}, {"bufferView", T::Uint}});
    });
    v.each(root, "samplers", [&](const json& o, const std::string& p) {
        v.object(o, p, {{"magFilter", T::Uint}, {"minFilter", T::Uint}, {"wrapS", T::Uint}, {"wrapT", T::Uint}});
    });

    // The references a bake follows and writes through: a primitive's
    // material, a material's textures, a texture's image. One that points past
    // its array is an invalid file (the Khronos validator's
    // UNRESOLVED_REFERENCE), refused here rather than written out again.
    const auto count = [&](const char* arr) {
        auto it = root.find(arr);
        return it == root.end() ? std::size_t(0) : it->size();
    };
    const auto resolves = [&](const json& o, const char* member, std::size_t n, const std::string& p) {
        if (auto it = o.find(member); it != o.end() && it->get<std::uint64_t>() >= n)
            throw Error(fmt::format("malformed glTF: '{}.{}' is {}, but the file has {} of them", p, member,
                                    it->get<std::uint64_t>(), n),
                        where);
    };
    v.each(root, "meshes", [&](const json& o, const std::string& p) {
        if (auto it = o.find("primitives"); it != o.end())
            for (std::size_t i = 0; i < it->size(); ++i)
                resolves((*it)[i], "material", count("materials"), fmt::format("{}.primitives[{}]", p, i));
    });
    v.each(root, "materials", [&](const json& o, const std::string& p) {
        for (const char* t : {"normalTexture", "occlusionTexture", "emissiveTexture"})
            if (auto it = o.find(t); it != o.end())
                resolves(*it, "index", count("textures"), p + "." + t);
        if (auto pbr = o.find("pbrMetallicRoughness"); pbr != o.end())
            for (const char* t : {"baseColorTexture", "metallicRoughnessTexture"})
                if (auto it = pbr->find(t); it != pbr->end())
                    resolves(*it, "index", count("textures"), p + ".pbrMetallicRoughness." + t);
    });
    v.each(root, "textures", [&](const json& o, const std::string& p) { resolves(o, "source", count("images"), p); });
}

std::uint32_t read_u32(const unsigned char* p) {
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

} // namespace

int check_gltf(const void* data, std::size_t size, bool binary, const std::string& where) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    const char* text = static_cast<const char*>(data);
    std::size_t text_size = size;
    if (binary) {
        if (size < 20 || std::memcmp(bytes, "glTF", 4) != 0)
            throw Error("not a binary glTF file (no 'glTF' magic)", where);
        const std::uint32_t version = read_u32(bytes + 4);
        if (version == 1)
            throw Error("binary glTF 1.0 is not supported; convert the file to glTF 2.0", where);
        if (version != 2)
            throw Error(fmt::format("unsupported binary glTF version {}", version), where);
        const std::uint32_t json_len = read_u32(bytes + 12);
        if (std::memcmp(bytes + 16, "JSON", 4) != 0 || json_len > size - 20)
            throw Error("binary glTF has no valid JSON chunk", where);
        text = reinterpret_cast<const char*>(bytes + 20);
        text_size = json_len;
    }
    json root = json::parse(text, text + text_size, nullptr, false);
    if (root.is_discarded())
        throw Error("malformed glTF: the JSON does not parse", where);
    if (!root.is_object() || !root.contains("asset") || !root["asset"].is_object())
        throw Error("malformed glTF: no 'asset' object", where);
    const json& asset = root["asset"];
    // glTF 2 requires asset.version "2.x"; anything else is treated as glTF 1
    // (whose files say 1, "1.0", or nothing), which Assimp reads.
    auto it = asset.find("version");
    if (it == asset.end() || !it->is_string() || it->get<std::string>().rfind("2.", 0) != 0)
        return 1;
    validate(root, where);
    // Compressed geometry would need a decoder skybake does not ship.
    if (auto req = root.find("extensionsRequired"); req != root.end())
        for (const auto& e : *req) {
            const auto name = e.get<std::string>();
            if (name == "KHR_draco_mesh_compression" || name == "EXT_meshopt_compression" ||
                name == "KHR_mesh_quantization")
                throw Error(fmt::format("the file requires glTF extension {}, which skybake does not support; "
                                        "export it without mesh compression",
                                        name),
                            where);
        }
    return 2;
}

} // namespace skybake::io
