"""Write hairmeshes/sintel_hair.abc: the strands of hairmeshes/sintel_hair.tfx as Alembic
(Ogawa) curves, with Blender's exporter (which links the reference Alembic library).

Run once, on a machine with Blender's Python module (`pip install bpy`, Python 3.11):

    python tools/alembic/make_sample.py hairmeshes/sintel_hair.tfx hairmeshes/sintel_hair.abc

What it writes, so the reader's test can check every part of it:
- two curve objects: strands 0..114 in `groom_front`, parented to an empty `groom_rig` that
  is rotated, scaled and moved, and strands 114..228 in `groom_back` at the root; the points of
  both are stored so that their world positions are the .tfx positions (the reader must compose
  the transform hierarchy to get them back);
- every point's radius is 0.001 * (1 - 0.8 t) in world units (t: 0 at the root, 1 at the
  tip); Blender writes twice the radius as the curves' widths, in the object's units (so the
  front strands store 1/1.5 of it and the reader must scale them back);
- Blender converts its Z-up world to Alembic's Y-up: the script stores a .tfx point (x, y, z)
  as Blender's (x, -z, y), which the export turns back into (x, y, z).
"""

import struct
import sys

import bpy
from mathutils import Euler, Matrix, Vector


def read_tfx(path):
    data = open(path, "rb").read()
    _version, strands, verts, offset = struct.unpack_from("<fIII", data, 0)
    points = struct.unpack_from("<%df" % (strands * verts * 4), data, offset)
    return [
        [points[(s * verts + v) * 4:(s * verts + v) * 4 + 3] for v in range(verts)]
        for s in range(strands)
    ]


def radius(v, count):
    return 0.001 * (1.0 - 0.8 * v / (count - 1))


def curve_object(name, strands, world_to_local, scale):
    curve = bpy.data.curves.new(name, type="CURVE")
    curve.dimensions = "3D"
    for strand in strands:
        spline = curve.splines.new("POLY")
        spline.points.add(len(strand) - 1)
        for v, (x, y, z) in enumerate(strand):
            local = world_to_local @ Vector((x, -z, y))
            spline.points[v].co = (local.x, local.y, local.z, 1.0)
            # Radii are in the object's own units: divide by its scale.
            spline.points[v].radius = radius(v, len(strand)) / scale
    obj = bpy.data.objects.new(name, curve)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def main(tfx, out):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    strands = read_tfx(tfx)
    half = len(strands) // 2
    rig = bpy.data.objects.new("groom_rig", None)
    bpy.context.scene.collection.objects.link(rig)
    rig.location = (0.05, -0.02, 0.1)
    rig.rotation_euler = Euler((0.3, -0.2, 0.7))
    rig.scale = (1.5, 1.5, 1.5)
    bpy.context.view_layer.update()
    front = curve_object("groom_front", strands[:half], rig.matrix_world.inverted(), 1.5)
    front.parent = rig
    curve_object("groom_back", strands[half:], Matrix.Identity(4), 1.0)
    bpy.context.view_layer.update()
    bpy.ops.wm.alembic_export(filepath=out, selected=False, start=1, end=1)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
