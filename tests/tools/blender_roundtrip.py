# tests/tools/blender_roundtrip.py — run by Blender (blender -b --factory-startup --python THIS --
# IN.glb OUT.json): import a glTF exported by `prtbake export` with Blender's own glTF add-on, as an
# artist opens it, and write what Blender holds: every mesh vertex's position (converted back to
# glTF's Y-up frame, which Blender's import turned into its Z-up one: (x, y, z) -> (x, -z, y)), its
# colour from the colour attribute (every corner of a vertex must agree), the polygons as vertex
# lists, and the attribute names. The C++ test (test_blender_roundtrip.cpp) compares it with the bake.
import json
import sys

import bpy
import numpy

# Debian 12's Blender 3.4 glTF add-on still spells numpy.bool, which NumPy 1.24 removed: the
# importer fails on every file without this alias (it is what the add-on meant, the builtin bool).
if not hasattr(numpy, "bool"):
    numpy.bool = bool

src, dst = sys.argv[sys.argv.index("--") + 1:][:2]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=src)
meshes = []
for ob in bpy.data.objects:
    if ob.type != "MESH":
        continue
    me = ob.data
    world = ob.matrix_world
    colours = [None] * len(me.vertices)
    disagree = 0
    layer = me.color_attributes.active_color if me.color_attributes else None
    if layer is not None:
        for loop in me.loops:
            c = tuple(layer.data[loop.index].color)
            if layer.domain == "POINT":
                c = tuple(layer.data[loop.vertex_index].color)
            if colours[loop.vertex_index] is not None and colours[loop.vertex_index] != c:
                disagree += 1
            colours[loop.vertex_index] = c
    positions = []
    for v in me.vertices:
        p = world @ v.co
        positions.append([p.x, p.z, -p.y])
    meshes.append({
        "name": ob.name,
        "positions": positions,
        "colours": colours,
        "colour_layer": None if layer is None else [layer.name, layer.domain, layer.data_type],
        "corners_disagreeing": disagree,
        "polygons": [list(p.vertices) for p in me.polygons],
        "attributes": sorted(a.name for a in me.attributes if not a.name.startswith(".")),
    })
with open(dst, "w") as f:
    json.dump({"blender": bpy.app.version_string, "meshes": meshes}, f)
print("prt-roundtrip: wrote", dst)
