"""Blender meshes to one skybake scene and the bake's results back.

The scene is every selected mesh object's EVALUATED mesh (modifiers, shape
keys and constraints applied: what the viewport shows), triangulated with
loop_triangles and put in world space with matrix_world, all in one
skybake.Mesh so that the objects occlude each other. Vertex normals are
Blender's (of the evaluated mesh), moved with the inverse transpose of
matrix_world; a mirroring matrix (negative determinant) also reverses the
triangles' winding so that front faces stay front faces.

Results go back onto each object's original mesh (obj.data), as Blender
attributes:

- point domain when the evaluated mesh has the original vertex count (no
  modifier, or modifiers that only move vertices): value i of the
  evaluated mesh is the value of original vertex i;
- corner (face-corner) domain when the vertex count changed but the corner
  count did not (Edge Split, and other modifiers that split vertices but
  keep the faces): corner l takes the value of the evaluated vertex of
  evaluated corner l;
- otherwise (Subdivision Surface, Boolean, ... change the topology) point
  domain again, each original vertex taking the value of the nearest
  evaluated vertex in object space, and the operator warns.

Attributes written (see ATTRIBUTES): skybake_ao and skybake_shading
(FLOAT), skybake_bent_normal (FLOAT_VECTOR, unit, WORLD space) and
skybake_ao_color (FLOAT_COLOR (ao, ao, ao, 1), the one the viewport shows;
a mesh's attribute names are unique across types, so the colour cannot
also be called skybake_ao).
"""

import numpy as np

AO = "skybake_ao"
SHADING = "skybake_shading"
BENT_NORMAL = "skybake_bent_normal"
AO_COLOR = "skybake_ao_color"
ATTRIBUTES = (AO, SHADING, BENT_NORMAL, AO_COLOR)


class ConversionError(Exception):
    """A selected object that cannot be baked; the message says why and what to do."""


class ObjectPart:
    """One object's slice of the scene mesh and how to map it back."""

    def __init__(self, name, first_vertex, vertex_count, corner_vertices, positions_object):
        self.name = name
        self.first_vertex = first_vertex
        self.vertex_count = vertex_count  # evaluated vertices
        self.corner_vertices = corner_vertices  # (L,) evaluated vertex of each evaluated corner
        self.positions_object = positions_object  # (N, 3) evaluated, object space (nearest fallback)

    @property
    def stop(self):
        return self.first_vertex + self.vertex_count


class SceneArrays:
    """World-space arrays of all the objects, ready for skybake.Mesh."""

    def __init__(self, positions, normals, indices, parts):
        self.positions = positions  # (N, 3) float32, world space
        self.normals = normals  # (N, 3) float32, unit, world space
        self.indices = indices  # (M, 3) uint32
        self.parts = parts

    @property
    def vertex_count(self):
        return len(self.positions)

    @property
    def triangle_count(self):
        return len(self.indices)

    def to_skybake(self, sb):
        return sb.Mesh(self.positions, self.indices, self.normals)


def _matrix(m):
    return np.array([list(row) for row in m], dtype=np.float64)


def _evaluated_arrays(obj, depsgraph):
    """Object-space positions, normals, triangles and corner vertices of the evaluated mesh."""
    eval_obj = obj.evaluated_get(depsgraph)
    mesh = eval_obj.to_mesh()
    try:
        if mesh is None:
            raise ConversionError(f"object '{obj.name}' has no mesh to bake")
        mesh.calc_loop_triangles()
        nv, nt, nl = len(mesh.vertices), len(mesh.loop_triangles), len(mesh.loops)
        positions = np.empty(nv * 3, np.float32)
        mesh.vertices.foreach_get("co", positions)
        normals = np.empty(nv * 3, np.float32)
        if hasattr(mesh, "vertex_normals"):
            mesh.vertex_normals.foreach_get("vector", normals)
        else:
            mesh.vertices.foreach_get("normal", normals)
        triangles = np.empty(nt * 3, np.int64)
        mesh.loop_triangles.foreach_get("vertices", triangles)
        corners = np.empty(nl, np.int64)
        mesh.loops.foreach_get("vertex_index", corners)
        world = _matrix(eval_obj.matrix_world)
    finally:
        eval_obj.to_mesh_clear()
    if nt == 0:
        raise ConversionError(
            f"object '{obj.name}' has no faces ({nv} vertices, 0 triangles): skybake bakes triangle meshes; "
            "add faces or deselect it")
    return positions.reshape(nv, 3), normals.reshape(nv, 3), triangles.reshape(nt, 3), corners, world


def gather(objects, depsgraph):
    """One world-space scene of the given mesh objects, in their order."""
    all_pos, all_nrm, all_tri, parts = [], [], [], []
    first = 0
    for obj in objects:
        if obj.type != "MESH":
            raise ConversionError(f"object '{obj.name}' is a {obj.type.lower()}, not a mesh; deselect it")
        pos, nrm, tri, corners, world = _evaluated_arrays(obj, depsgraph)
        linear, translation = world[:3, :3], world[:3, 3]
        det = np.linalg.det(linear)
        if not np.isfinite(det) or abs(det) < 1e-30:
            raise ConversionError(f"object '{obj.name}' has a degenerate transform (scale 0): fix its scale")
        pos_w = pos.astype(np.float64) @ linear.T + translation
        nrm_w = nrm.astype(np.float64) @ np.linalg.inv(linear)  # (M^-T n) as rows
        length = np.linalg.norm(nrm_w, axis=1)
        bad = ~(length > 1e-20)
        nrm_w[~bad] /= length[~bad, None]
        nrm_w[bad] = (0.0, 0.0, 1.0)  # loose vertices: any unit vector
        if det < 0.0:
            tri = tri[:, [0, 2, 1]]
        all_pos.append(pos_w)
        all_nrm.append(nrm_w)
        all_tri.append(tri + first)
        parts.append(ObjectPart(obj.name, first, len(pos), corners, pos))
        first += len(pos)
    if not parts:
        raise ConversionError("no mesh objects selected: select the meshes to bake")
    positions = np.ascontiguousarray(np.concatenate(all_pos), dtype=np.float32)
    normals = np.ascontiguousarray(np.concatenate(all_nrm), dtype=np.float32)
    indices = np.ascontiguousarray(np.concatenate(all_tri), dtype=np.uint32)
    if not np.all(np.isfinite(positions)):
        raise ConversionError("a selected object has non-finite vertex positions")
    return SceneArrays(positions, normals, indices, parts)


def _nearest(original, evaluated):
    """For each original vertex, the index of the nearest evaluated vertex."""
    from mathutils import kdtree

    tree = kdtree.KDTree(len(evaluated))
    for i, co in enumerate(evaluated):
        tree.insert(co, i)
    tree.balance()
    return np.fromiter((tree.find(co)[1] for co in original), dtype=np.int64, count=len(original))


def remove_attributes(mesh):
    for name in ATTRIBUTES:
        attr = mesh.attributes.get(name)
        while attr is not None:
            mesh.attributes.remove(attr)
            attr = mesh.attributes.get(name)


def write_back(obj, part, ao, shading, bent_normal):
    """Writes one object's slice of the results onto obj.data. Returns the domain used and whether it
    had to fall back to nearest vertices."""
    mesh = obj.data
    ao = np.asarray(ao[part.first_vertex:part.stop], dtype=np.float32)
    shading = np.asarray(shading[part.first_vertex:part.stop], dtype=np.float32)
    bent = np.asarray(bent_normal[part.first_vertex:part.stop], dtype=np.float32)
    nearest = False
    if len(mesh.vertices) == part.vertex_count:
        domain, pick = "POINT", None
    elif len(mesh.loops) == len(part.corner_vertices):
        domain, pick = "CORNER", part.corner_vertices
    else:
        original = np.empty(len(mesh.vertices) * 3, np.float32)
        mesh.vertices.foreach_get("co", original)
        domain, pick, nearest = "POINT", _nearest(original.reshape(-1, 3), part.positions_object), True
    if pick is not None:
        ao, shading, bent = ao[pick], shading[pick], bent[pick]

    remove_attributes(mesh)
    mesh.attributes.new(AO, "FLOAT", domain).data.foreach_set("value", ao)
    mesh.attributes.new(SHADING, "FLOAT", domain).data.foreach_set("value", shading)
    mesh.attributes.new(BENT_NORMAL, "FLOAT_VECTOR", domain).data.foreach_set("vector", bent.ravel())
    color = np.ones((len(ao), 4), np.float32)
    color[:, 0] = color[:, 1] = color[:, 2] = ao
    color_attr = mesh.color_attributes.new(AO_COLOR, "FLOAT_COLOR", domain)
    color_attr.data.foreach_set("color", color.ravel())
    _make_active_color(mesh, AO_COLOR)
    mesh.update()
    return domain, nearest


def _make_active_color(mesh, name):
    colors = mesh.color_attributes
    for attr_name in ("active_color_name", "default_color_name"):  # Blender 3.5+
        if hasattr(colors, attr_name):
            try:
                setattr(colors, attr_name, name)
            except (AttributeError, TypeError):
                pass
    index = next((i for i, a in enumerate(colors) if a.name == name), -1)
    if index >= 0:
        for attr_name in ("active_color_index", "render_color_index"):
            if hasattr(colors, attr_name):
                try:
                    setattr(colors, attr_name, index)
                except (AttributeError, TypeError):
                    pass
    try:
        colors.active_color = colors[name]
    except (AttributeError, TypeError, KeyError):
        pass


def read_back(mesh, name):
    """(values, domain) of a float, vector or colour attribute written here (for tests and scripts)."""
    attr = mesh.attributes[name]
    width = {"FLOAT": 1, "FLOAT_VECTOR": 3, "FLOAT_COLOR": 4}[attr.data_type]
    key = {"FLOAT": "value", "FLOAT_VECTOR": "vector", "FLOAT_COLOR": "color"}[attr.data_type]
    values = np.empty(len(attr.data) * width, np.float32)
    attr.data.foreach_get(key, values)
    return (values if width == 1 else values.reshape(-1, width)), attr.domain
