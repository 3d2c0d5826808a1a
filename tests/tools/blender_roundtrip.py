# tests/tools/blender_roundtrip.py — run by Blender (blender -b --factory-startup --python THIS --
# IN.glb OUT.json): import a glTF exported by `prtbake export` with Blender's own glTF add-on, as an
# artist opens it, and write what Blender holds: every mesh vertex's position (converted back to
# glTF's Y-up frame, which Blender's import turned into its Z-up one: (x, y, z) -> (x, -z, y)), its
# colour from the colour attribute (every corner of a vertex must agree), the polygons as vertex
# lists, the attribute names, the UV maps (per loop) and where the material's occlusion texture
# landed (group node, image, UV map, pixels). The C++ test (test_blender_roundtrip.cpp) compares it with the bake.
import json
import sys

import bpy
import numpy

# Debian 12's Blender 3.4 glTF add-on still spells numpy.bool, which NumPy 1.24 removed: the
# importer fails on every file without this alias (it is what the add-on meant, the builtin bool).
if not hasattr(numpy, "bool"):
    numpy.bool = bool


def source_node(socket):
    """The node feeding `socket`, through any node in between (Separate RGB), up to an image."""
    while socket.is_linked:
        node = socket.links[0].from_node
        if node.type == "TEX_IMAGE" or not node.inputs:
            return node
        socket = next((i for i in node.inputs if i.is_linked), node.inputs[0])
    return None


def occlusion_of(material):
    """Where Blender's glTF importer put the material's occlusionTexture: the "glTF Settings" (3.x) or
    "glTF Material Output" (4.x) group node's Occlusion input, the image feeding it, its UV map
    and its pixels' red channel, row 0 at the bottom (Blender's order)."""
    if not material.use_nodes:
        return None
    for node in material.node_tree.nodes:
        if node.type != "GROUP" or node.node_tree is None or "Occlusion" not in node.inputs:
            continue
        image_node = source_node(node.inputs["Occlusion"])
        if image_node is None or image_node.type != "TEX_IMAGE" or image_node.image is None:
            return {"group": node.node_tree.name, "image": None}
        uv = source_node(image_node.inputs["Vector"]) if image_node.inputs["Vector"].is_linked else None
        image = image_node.image
        pixels = list(image.pixels)
        return {
            "group": node.node_tree.name,
            "image": image.name,
            "colorspace": image.colorspace_settings.name,
            "size": list(image.size),
            "red": pixels[0::4],
            "uv_map": uv.uv_map if uv is not None and uv.type == "UVMAP" else None,
        }
    return None


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
    occlusion = [occlusion_of(slot.material) for slot in ob.material_slots if slot.material is not None]
    meshes.append({
        "name": ob.name,
        "positions": positions,
        "colours": colours,
        "colour_layer": None if layer is None else [layer.name, layer.domain, layer.data_type],
        "corners_disagreeing": disagree,
        "polygons": [list(p.vertices) for p in me.polygons],
        "attributes": sorted(a.name for a in me.attributes if not a.name.startswith(".")),
        "uv_layers": [uv.name for uv in me.uv_layers],
        "uvs": [[[uv.data[loop.index].uv[0], uv.data[loop.index].uv[1]] for loop in me.loops] for uv in me.uv_layers],
        "loop_vertices": [loop.vertex_index for loop in me.loops],
        "occlusion": [o for o in occlusion if o is not None],
    })
with open(dst, "w") as f:
    json.dump({"blender": bpy.app.version_string, "meshes": meshes}, f)
print("prt-roundtrip: wrote", dst)
