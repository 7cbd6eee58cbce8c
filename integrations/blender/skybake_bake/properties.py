"""Scene settings shown in the panel and used as the operators' defaults."""

import math

import bpy

from . import module_loader

RULES = (
    ("lebedev:590", "Lebedev 590", "Lebedev–Laikov rule, 590 directions (the CLI's default)"),
    ("lebedev:194", "Lebedev 194", "Lebedev–Laikov rule, 194 directions (fast preview)"),
    ("lebedev:2030", "Lebedev 2030", "Lebedev–Laikov rule, 2030 directions"),
    ("lebedev:5810", "Lebedev 5810", "Lebedev–Laikov rule, 5810 directions (reference quality)"),
    ("design:t21", "Spherical design t21", "Spherical t-design of strength 21"),
    ("fibonacci:1000", "Fibonacci 1000", "1000 directions on a Fibonacci spiral"),
    ("CUSTOM", "Custom", "Any rule the CLI accepts (see 'skybake sphere list')"),
)

BACK_FACES = (
    ("occlude", "Occlude", "Both sides of a triangle block rays"),
    ("ignore", "Ignore", "Rays pass through triangles seen from behind (open, single-sided meshes)"),
)

_backend_items = []  # Blender keeps pointers into the strings: hold them here


def backend_items(self, context):
    items = [(name, name, summary or f"skybake visibility backend '{name}'")
             for name, available, _, summary in module_loader.backends() if available]
    if not items:
        items = [("embree", "embree", "skybake visibility backend 'embree'")]
    _backend_items[:] = items
    return _backend_items


def rule_spec(settings):
    return settings.rule_custom.strip() if settings.rule == "CUSTOM" else settings.rule


def max_distance(settings):
    """The module's max_distance: 0 in the UI means unlimited."""
    return settings.max_distance if settings.max_distance > 0.0 else math.inf


class SkybakeSettings(bpy.types.PropertyGroup):
    rule: bpy.props.EnumProperty(name="Rule", items=RULES, default="lebedev:590",
                                 description="Sphere quadrature rule: the ray directions")
    rule_custom: bpy.props.StringProperty(name="Custom rule", default="lebedev:590",
                                          description="e.g. lebedev:5810, design:t21, fibonacci:1000, mc:4096")
    max_distance: bpy.props.FloatProperty(name="Max distance", default=0.0, min=0.0, soft_max=100.0,
                                          subtype="DISTANCE", unit="LENGTH",
                                          description="Ignore occluders further than this (world units); 0: unlimited")
    offset: bpy.props.FloatProperty(name="Offset", default=0.0, min=0.0, max=1e17, soft_max=0.1, precision=4,
                                    subtype="DISTANCE", unit="LENGTH",
                                    description="Move ray origins this much along the normal (world units)")
    back_faces: bpy.props.EnumProperty(name="Back faces", items=BACK_FACES, default="occlude")
    backend: bpy.props.EnumProperty(name="Backend", items=backend_items,
                                    description="Visibility backend (only those that can run here)")

    sun_elevation_deg: bpy.props.FloatProperty(name="Sun elevation", default=30.0, min=-90.0, max=90.0,
                                               description="Degrees above the horizon")
    sun_azimuth_deg: bpy.props.FloatProperty(name="Sun azimuth", default=135.0, min=-360.0, max=360.0,
                                             description="Degrees clockwise from +Y (north) towards +X (east)")
    sky_strength: bpy.props.FloatProperty(name="Strength", default=1.0, min=0.0, soft_max=10.0,
                                          description="Background node strength")
    sky_width: bpy.props.IntProperty(name="Width", default=1024, min=16, max=8192,
                                     description="Panorama width in pixels (height: half of it)")
    atmosphere: bpy.props.StringProperty(name="Atmosphere", default="earth",
                                         description="skybake atmosphere preset ('earth', 'paper', 'paper-dense')")
