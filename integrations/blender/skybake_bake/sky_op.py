"""The sky operator: the World background as a skybake sky.

It renders skybake's reference sky as an equirectangular panorama (2:1,
linear radiance per unit sun irradiance: strength 1 matches a Sun lamp of
strength 1), writes it as an EXR and wires Texture Coordinate (Generated)
→ Mapping → Environment Texture → Background → World Output.

Orientation. skybake's panorama has azimuth 0..360° from left to right
(clockwise seen from above: north, east, south, west) and elevation +90° at
the top. Blender's equirectangular lookup puts -X at the left edge, +Y a
quarter of the way in, +X at the centre and -Y at three quarters. The
Mapping node turns the lookup by +90° about Z so that skybake's azimuth is
Blender's compass: azimuth 0 = +Y (north), 90° = +X (east); the sun lies in
the world direction (cos e sin a, cos e cos a, sin e) for elevation e and
azimuth a. tests/blender/test_addon.py checks it with a Cycles render.

From the UI (invoke()) the panorama renders in a thread, with its progress
in the status bar and Esc to cancel, so that Blender keeps drawing: 8192
pixels wide takes about 20 s on two cores. execute() (scripts, `blender -b`)
renders in place.
"""

import math
import os

import bpy

from . import job, module_loader

IMAGE_NAME = "skybake_sky"
WORLD_NAME = "skybake sky"


def sun_direction(elevation_deg, azimuth_deg):
    """World-space unit vector towards the sun, in the convention above."""
    e, a = math.radians(elevation_deg), math.radians(azimuth_deg)
    return (math.cos(e) * math.sin(a), math.cos(e) * math.cos(a), math.sin(e))


def build_world(world, image, strength):
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    nodes.clear()
    coords = nodes.new("ShaderNodeTexCoord")
    coords.location = (-900, 0)
    mapping = nodes.new("ShaderNodeMapping")
    mapping.name = mapping.label = "skybake orientation"
    mapping.vector_type = "POINT"
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.pi / 2.0)
    mapping.location = (-700, 0)
    env = nodes.new("ShaderNodeTexEnvironment")
    env.image = image
    env.projection = "EQUIRECTANGULAR"
    env.interpolation = "Linear"
    env.location = (-450, 0)
    background = nodes.new("ShaderNodeBackground")
    background.inputs["Strength"].default_value = strength
    background.location = (-150, 0)
    output = nodes.new("ShaderNodeOutputWorld")
    output.location = (100, 0)
    links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    links.new(env.outputs["Color"], background.inputs["Color"])
    links.new(background.outputs["Background"], output.inputs["Surface"])


class SKYBAKE_OT_sky_world(job.ModalJob, bpy.types.Operator):
    """Set the World background to a skybake sky (equirectangular EXR) for a sun elevation and azimuth"""

    bl_idname = "skybake.sky_world"
    bl_label = "Set Sky World"
    bl_options = {"REGISTER", "UNDO"}

    sun_elevation_deg: bpy.props.FloatProperty(name="Sun elevation", default=30.0, min=-90.0, max=90.0,
                                               description="Degrees above the horizon")
    sun_azimuth_deg: bpy.props.FloatProperty(name="Sun azimuth", default=135.0, min=-360.0, max=360.0,
                                             description="Degrees clockwise from +Y (north) towards +X (east)")
    strength: bpy.props.FloatProperty(name="Strength", default=1.0, min=0.0, soft_max=10.0)
    width: bpy.props.IntProperty(name="Width", default=1024, min=16, max=8192,
                                 description="Panorama width in pixels; the height is half of it")
    atmosphere: bpy.props.StringProperty(name="Atmosphere", default="earth",
                                         description="skybake atmosphere preset")
    sun_disc: bpy.props.BoolProperty(name="Sun disc", default=True,
                                     description="Include the sun's disc (off: add a Sun lamp instead)")
    filepath: bpy.props.StringProperty(name="File", default="", subtype="FILE_PATH",
                                       description="EXR to write; empty: Blender's temporary folder, packed "
                                                   "into the .blend")

    @classmethod
    def poll(cls, context):
        if job.running is not None:
            cls.poll_message_set("a skybake job is running (Esc cancels it)")
            return False
        return True

    def _render_job(self):
        """The panorama as a job, or None after reporting why."""
        sb = module_loader.get()
        if sb is None:
            self.report({"ERROR"}, module_loader.problem())
            return None
        width = self.width + (self.width % 2)
        atmosphere = self.atmosphere.strip() or "earth"
        settings = dict(view="panorama", sun_elevation_deg=self.sun_elevation_deg,
                        sun_azimuth_deg=self.sun_azimuth_deg % 360.0, altitude_km=0.0, sun_disc=self.sun_disc)

        def render(progress):
            sky = sb.Sky.reference(sb.atmosphere_preset(atmosphere))
            return sky.render(width, width // 2, progress=progress, **settings)

        self._sb, self._width = sb, width
        return job.Job(render)

    def execute(self, context):
        render = self._render_job()
        if render is None:
            return {"CANCELLED"}
        render.run()
        return self._finish(context, render)

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        render = self._render_job()
        if render is None:
            return {"CANCELLED"}
        return self._start_modal(context, render)

    def _describe(self):
        return f"rendering a {self._width}x{self._width // 2} sky"

    def _done(self, context):
        return self._finish(context, self._job)

    def _finish(self, context, render):
        sb, width = self._sb, self._width
        if render.cancelled:
            self.report({"WARNING"}, "skybake: sky cancelled, the World is unchanged")
            return {"CANCELLED"}
        if render.error is not None:
            self.report({"ERROR"}, f"skybake: {job.error_text(render.error)}")
            return {"CANCELLED"}
        rgb = render.result
        packed = not self.filepath.strip()
        path = (bpy.path.abspath(self.filepath) if not packed else
                os.path.join(bpy.app.tempdir, f"skybake_sky_e{self.sun_elevation_deg:g}_a{self.sun_azimuth_deg:g}.exr"))
        if not path.lower().endswith(".exr"):
            path += ".exr"
        try:
            os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
            sb.save_image(path, rgb)
        except (OSError, sb.Error) as e:
            self.report({"ERROR"}, f"skybake: cannot write {path}: {getattr(e, 'message', None) or e}")
            return {"CANCELLED"}

        image = bpy.data.images.get(IMAGE_NAME)
        if image is not None and image.packed_file is not None:
            image.unpack(method="REMOVE")
        if image is None:
            image = bpy.data.images.load(path, check_existing=False)
            image.name = IMAGE_NAME
        else:
            image.filepath = path
            image.reload()
        if packed:
            image.pack()

        world = context.scene.world
        if world is None:
            world = bpy.data.worlds.get(WORLD_NAME) or bpy.data.worlds.new(WORLD_NAME)
            context.scene.world = world
        build_world(world, image, self.strength)
        world["skybake_sun_elevation_deg"] = self.sun_elevation_deg
        world["skybake_sun_azimuth_deg"] = self.sun_azimuth_deg
        world["skybake_atmosphere"] = self.atmosphere
        if self.sun_disc and width < 940:
            self.report({"WARNING"}, f"skybake: at {width} pixels wide the sun's disc (0.27° in radius) can fall "
                        "between pixel centres and vanish; use 1024 or more")
        self.report({"INFO"}, f"skybake: World '{world.name}' set to a {width}x{width // 2} sky, sun at "
                    f"elevation {self.sun_elevation_deg:g}°, azimuth {self.sun_azimuth_deg:g}°")
        return {"FINISHED"}
