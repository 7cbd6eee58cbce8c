# Suzanne with Smart UV Project, exported as the argument after "--" names it
# (.glb or .gltf); "material" gives her a plain Principled BSDF (a material
# without textures), "bare" none.
#   blender -b --factory-startup --python make_suzanne.py -- OUT.glb material
import sys, bpy
out, kind = sys.argv[sys.argv.index("--") + 1:][:2]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.mesh.primitive_monkey_add()
obj = bpy.context.active_object
bpy.ops.object.shade_smooth()
bpy.ops.object.mode_set(mode="EDIT")
bpy.ops.mesh.select_all(action="SELECT")
bpy.ops.uv.smart_project()
bpy.ops.object.mode_set(mode="OBJECT")
if kind == "material":
    mat = bpy.data.materials.new("Clay")
    mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.8, 0.3, 0.2, 1.0)
    obj.data.materials.append(mat)
fmt = "GLB" if out.endswith(".glb") else "GLTF_SEPARATE"
bpy.ops.export_scene.gltf(filepath=out, export_format=fmt)
