// skybake.Mesh: triangle meshes, import, export and procedural generation
// (skybake/mesh.h).
//
// A Mesh owns its arrays (the library's std::vectors). Reading a property
// (positions, normals, ...) returns a copy as a NumPy array, so that no
// array can outlive or alias storage that a later bake or assignment
// reallocates; assigning one copies it in.
#include <cstring>

#include "common.h"
#include "skybake/files.h"
#include "skybake/gltf_asset.h"
#include "skybake/mesh.h"

namespace skybake::python {

namespace {

template <class Vec>
py::array_t<float> rows_copy(const std::vector<Vec>& rows) {
    constexpr int n = int(sizeof(Vec) / sizeof(float));
    std::vector<float> flat(rows.size() * n);
    if (!rows.empty())
        std::memcpy(flat.data(), rows.data(), flat.size() * sizeof(float));
    return to_numpy(std::move(flat), {py::ssize_t(rows.size()), n});
}

template <class Vec>
std::vector<Vec> rows_from(const py::handle& obj, const char* name, bool finite) {
    constexpr int n = int(sizeof(Vec) / sizeof(float));
    const auto arr = checked_array<float>(obj, name, {-1, n}, finite);
    std::vector<Vec> rows(std::size_t(arr.shape(0)));
    if (!rows.empty())
        std::memcpy(rows.data(), arr.data(), rows.size() * sizeof(Vec));
    return rows;
}

py::array_t<std::uint32_t> indices_copy(const Mesh& mesh) {
    std::vector<std::uint32_t> idx = mesh.indices;
    return to_numpy(std::move(idx), {py::ssize_t(mesh.triangle_count()), 3});
}

std::vector<std::uint32_t> indices_from(const py::handle& obj) {
    const auto arr = checked_array<std::uint32_t>(obj, "indices", {-1, 3});
    return {arr.data(), arr.data() + arr.size()};
}

Mesh mesh_from_arrays(const py::handle& positions, const py::handle& indices, const py::handle& normals,
                      const py::handle& colors) {
    Mesh mesh;
    mesh.positions = rows_from<glm::vec3>(positions, "positions", true);
    mesh.indices = indices_from(indices);
    if (!normals.is_none())
        mesh.normals = rows_from<glm::vec3>(normals, "normals", true);
    if (!colors.is_none())
        mesh.colors = rows_from<glm::vec4>(colors, "colors", true);
    validate_mesh(mesh, "mesh");
    return mesh;
}

} // namespace

void bind_mesh(py::module_& m) {
    py::class_<Mesh>(m, "Mesh",
                     "A triangle mesh in world space: parallel per-vertex arrays and 3 indices per triangle "
                     "(counter-clockwise front faces). Properties return copies; assign to change them.")
        .def(py::init(&mesh_from_arrays), py::arg("positions"), py::arg("indices"), py::arg("normals") = py::none(),
             py::arg("colors") = py::none(),
             "From arrays (copied): positions (N, 3) float32, indices (M, 3) uint32, optional unit normals "
             "(N, 3) float32 and linear RGBA colours (N, 4) float32. Raises skybake.Error for bad arrays, "
             "out-of-range indices or non-finite values.")
        .def_property_readonly("vertex_count", &Mesh::vertex_count)
        .def_property_readonly("triangle_count", &Mesh::triangle_count)
        .def_property(
            "positions", [](const Mesh& mesh) { return rows_copy(mesh.positions); },
            [](Mesh& mesh, const py::handle& a) { mesh.positions = rows_from<glm::vec3>(a, "positions", true); },
            "(N, 3) float32, world space.")
        .def_property(
            "normals", [](const Mesh& mesh) { return rows_copy(mesh.normals); },
            [](Mesh& mesh, const py::handle& a) { mesh.normals = rows_from<glm::vec3>(a, "normals", true); },
            "(N, 3) float32, unit; (0, 3) until computed.")
        .def_property(
            "colors", [](const Mesh& mesh) { return rows_copy(mesh.colors); },
            [](Mesh& mesh, const py::handle& a) { mesh.colors = rows_from<glm::vec4>(a, "colors", true); },
            "(N, 4) float32 linear RGBA in [0, 1]; (0, 4) when the mesh has none.")
        .def_property("indices", &indices_copy,
                      [](Mesh& mesh, const py::handle& a) { mesh.indices = indices_from(a); },
                      "(M, 3) uint32, three vertex indices per triangle.")
        .def_property_readonly(
            "texcoords",
            [](const Mesh& mesh) {
                py::list sets;
                for (const auto& uv : mesh.texcoords)
                    sets.append(rows_copy(uv));
                return sets;
            },
            "The UV sets, each (N, 2) float32 (glTF convention: v grows downwards).")
        .def_property_readonly(
            "attribute_names",
            [](const Mesh& mesh) {
                std::vector<std::string> names;
                for (const auto& a : mesh.attributes)
                    names.push_back(a.name);
                return names;
            },
            "Names of the per-vertex float attributes (\"ao\", \"shading\", \"bent_normal\", ...).")
        .def(
            "attribute",
            [](const Mesh& mesh, const std::string& name) {
                const VertexAttribute* a = mesh.find_attribute(name);
                if (!a)
                    throw Error("the mesh has no attribute '" + name + "'", "name");
                std::vector<float> values = a->values;
                if (a->components == 1)
                    return to_numpy(std::move(values), {py::ssize_t(mesh.vertex_count())});
                return to_numpy(std::move(values), {py::ssize_t(mesh.vertex_count()), a->components});
            },
            py::arg("name"), "A copy of an attribute: (N,) float32 for one component, else (N, C).")
        .def(
            "set_attribute",
            [](Mesh& mesh, const std::string& name, const py::handle& values) {
                if (!py::isinstance<py::array>(values))
                    throw Error("expected a NumPy array of float32", "values");
                const auto ndim = py::reinterpret_borrow<py::array>(values).ndim();
                const auto arr = ndim == 1 ? checked_array<float>(values, "values", {py::ssize_t(mesh.vertex_count())},
                                                                  /*finite=*/true)
                                           : checked_array<float>(values, "values",
                                                                  {py::ssize_t(mesh.vertex_count()), -1}, true);
                const int components = ndim == 1 ? 1 : int(arr.shape(1));
                if (components < 1 || components > 4)
                    throw Error("an attribute has 1 to 4 components, got " + std::to_string(components), "values");
                mesh.set_attribute(name, components, std::vector<float>(arr.data(), arr.data() + arr.size()));
            },
            py::arg("name"), py::arg("values"),
            "Adds or replaces an attribute from (N,) or (N, C) float32 (C ≤ 4), copied. Names are [a-z0-9_].")
        .def("compute_normals", &compute_normals, "Area-weighted vertex normals.")
        .def(
            "validate", [](const Mesh& mesh) { validate_mesh(mesh, "mesh"); },
            "Raises skybake.Error unless the arrays match in size, the indices are in range and positions finite.")
        .def(
            "bounds",
            [](const Mesh& mesh) {
                const Bounds b = compute_bounds(mesh);
                return py::make_tuple(py::make_tuple(b.min.x, b.min.y, b.min.z), py::make_tuple(b.max.x, b.max.y, b.max.z));
            },
            "((min x, y, z), (max x, y, z)).")
        .def("copy", [](const Mesh& mesh) { return Mesh(mesh); }, "A deep copy.")
        .def("__repr__", [](const Mesh& mesh) {
            return "Mesh(vertices=" + std::to_string(mesh.vertex_count()) +
                   ", triangles=" + std::to_string(mesh.triangle_count()) + ")";
        });

    m.def(
        "load_mesh",
        [](const std::filesystem::path& path) { return long_call(py::none(), [&] { return load_mesh(path); }); },
        py::arg("path"),
        "Reads any mesh skybake reads (glTF, PLY, and OBJ, STL, OFF, FBX, ... through Assimp). Normals are "
        "computed when the file has none. Raises skybake.Error for a missing, malformed or empty file.");
    m.def(
        "save_mesh",
        [](const std::filesystem::path& path, const Mesh& mesh, bool ascii) {
            long_call(py::none(),
                      [&] { save_mesh(path, mesh, ExportOptions{ascii ? PlyEncoding::Ascii : PlyEncoding::Binary}); });
        },
        py::arg("path"), py::arg("mesh"), py::arg("ascii") = false,
        "Writes .glb (attributes as \"_NAME\") or .ply (ascii: text PLY). Atomic.");
    py::class_<BakeFile>(
        m, "BakeFile",
        "A bake's mesh and the file it came from, written back through the one glTF path of the CLI: a glTF 2.0 "
        "input keeps its whole document (materials, textures, nodes, skins, animations, extensions) and gains "
        "the baked attributes; other inputs are written as a plain .glb or .ply.")
        .def(py::init([](const std::filesystem::path& input, const std::filesystem::path& output) {
                 return long_call(py::none(), [&] { return BakeFile::open(input, output); });
             }),
             py::arg("input"), py::arg("output"),
             "Reads INPUT for a bake that will write OUTPUT (.glb, .gltf or .ply). Raises skybake.Error as "
             "load_mesh() does, and for a .gltf output of an input that is not glTF 2.0.")
        .def_property_readonly(
            "mesh", [](BakeFile& f) -> Mesh& { return f.mesh(); }, py::return_value_policy::reference_internal,
            "The mesh, in place: bake it (bake_ao, bake_transfer, ...) and its attributes are what save() writes.")
        .def_property_readonly("has_document", [](BakeFile& f) { return f.document() != nullptr; },
                               "Whether the input's glTF document is kept.")
        .def(
            "save",
            [](const BakeFile& f, const std::filesystem::path& path, bool ascii) {
                long_call(py::none(), [&] {
                    OutputSet files;
                    f.save(files.stage(path), ExportOptions{ascii ? PlyEncoding::Ascii : PlyEncoding::Binary});
                    files.commit();
                });
            },
            py::arg("path"), py::arg("ascii") = false,
            "Writes the mesh with its attributes as `skybake ao` does (.glb, .gltf or .ply; ascii: text PLY). "
            "Atomic.");

    m.def(
        "generate_mesh",
        [](const std::string& kind, std::uint64_t triangles, std::uint64_t seed) {
            ProceduralOptions o;
            o.kind = parse_procedural_kind(kind);
            o.target_triangles = triangles;
            o.seed = seed;
            py::gil_scoped_release release;
            return generate_mesh(o);
        },
        py::arg("kind"), py::arg("triangles") = 20000, py::arg("seed") = 1,
        "A procedural mesh: 'sphere', 'terrain', 'city', 'bowl', 'wall' or 'torus', with about `triangles` "
        "triangles. Deterministic.");
    m.def("procedural_kinds", &procedural_kind_names, "The names generate_mesh() takes.");
}

} // namespace skybake::python
