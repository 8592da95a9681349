#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets into fuzz/corpus/<target>/ (ignored by
git): the shared Cornell box scene (TOML, OBJ, MTL) and small hand-written scenes, OBJ/MTL
pairs, glTF JSON and GLB files. Usage: python3 fuzz/make_seeds.py [SHARED_SCENES_DIR]"""
import base64, json, os, struct, sys

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = sys.argv[1] if len(sys.argv) > 1 else "/work/shared/scenes"
BOX = os.path.join(SCENES, "cornell-box")


def write(target, name, data):
    d = os.path.join(HERE, "corpus", target)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


def read(name):
    try:
        with open(os.path.join(BOX, name), "rb") as f:
            return f.read()
    except OSError:
        return None


# --- scene_toml: the fuzz target's directory holds tri.obj, tri.mtl, tri.gltf ---------
CAMERA = '[camera]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nfov_y_deg = 40.0\n'
LIGHT = '[[point_light]]\nposition = [0.0, 0.0, 3.0]\nintensity = [1.0, 1.0, 1.0]\n'
box = read("scene.toml")
if box:
    write("scene_toml", "cornell.toml", box.replace(b"CornellBox-Original.obj", b"tri.obj"))
write("scene_toml", "obj.toml", CAMERA + '[[mesh]]\npath = "tri.obj"\n' + LIGHT)
write("scene_toml", "full.toml",
      CAMERA + 'up = [0.0, 1.0, 0.0]\n[film]\nwidth = 64\nheight = 48\n'
      '[[mesh]]\npath = "tri.obj"\ndefault_material = "x"\n' + LIGHT +
      '[materials.red]\ndiffuse = [0.2, 0.2, 0.2]\nmirror = [0.5, 0.5, 0.5]\n'
      '[materials.x]\ndiffuse = [1.0, 1.0, 1.0]\n')
write("scene_toml", "gltf.toml", CAMERA + '[[mesh]]\npath = "tri.gltf"\n' + LIGHT +
      '[materials.g]\nmirror = [0.1, 0.1, 0.1]\n')
write("scene_toml", "two.toml", CAMERA + '[[mesh]]\npath = "tri.gltf"\n[[mesh]]\npath = "tri.obj"\n' + LIGHT + LIGHT)

# --- obj_mtl: OBJ, NUL, MTL ------------------------------------------------------------
obj, mtl = read("CornellBox-Original.obj"), read("CornellBox-Original.mtl")
if obj and mtl:
    write("obj_mtl", "cornell", obj.replace(b"CornellBox-Original.mtl", b"m.mtl") + b"\0" + mtl)
write("obj_mtl", "quad",
      "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 1\nvn 0 0 1\n"
      "usemtl a\nf 1/1/1 2/2/1 3/1/1 4/2/1\nusemtl t\nf -4 -2 -1\nl 1 2 3\nf 1 2\n\0"
      "newmtl a\nKd 0.5 0.4 0.3\nKs 0.1 0.1 0.1\nillum 5\nNs 10\nd 1\nmap_Kd x.png\n")
write("obj_mtl", "groups",
      "o a\ng b\nv 0 0 0\nv 1 0 0\nv 0 1 0 1\nv 1 1 1 2\nf 1 2 3\ng c\nusemtl d\nf 2 4 3\ns off\n")
write("obj_mtl", "colors", "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n")

# --- gltf: JSON with a data: URI, an external buffer, a texture; GLB -------------------
tri = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<3H", 0, 1, 2)


def doc(uri, extra=None, glb=False):
    d = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"children": [1], "translation": [0, 1, 0]},
                  {"mesh": 0, "scale": [2, 2, 2], "rotation": [0, 0, 0, 1]}],
        "meshes": [{"name": "m", "primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 2}, "indices": 1, "material": 0, "mode": 4}]}],
        "materials": [{"name": "g", "pbrMetallicRoughness": {
            "baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 1, "roughnessFactor": 0.1}}],
        "buffers": [{"byteLength": 42} if glb else {"byteLength": 42, "uri": uri}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
    }
    if extra:
        extra(d)
    return json.dumps(d, separators=(",", ":"))


data_uri = "data:application/octet-stream;base64," + base64.b64encode(tri).decode()
write("gltf", "data_uri.gltf", doc(data_uri))
write("gltf", "external.gltf", doc("b.bin"))


def textured(d):
    d["images"] = [{"uri": "t.png"}]
    d["textures"] = [{"source": 0}]
    d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}


def light(d):
    d["extensionsUsed"] = ["KHR_lights_punctual"]
    d["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"type": "point", "intensity": 100, "color": [1, 1, 1]}, {"type": "spot", "spot": {}}]}}
    d["nodes"][0]["extensions"] = {"KHR_lights_punctual": {"light": 0}}


def sparse(d):
    d["accessors"][0] = {"componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0], "sparse": {
        "count": 2, "indices": {"bufferView": 1, "componentType": 5123},
        "values": {"bufferView": 0}}}


def strip(d):
    d["meshes"][0]["primitives"][0]["mode"] = 5
    del d["meshes"][0]["primitives"][0]["indices"]


write("gltf", "texture.gltf", doc(data_uri, textured))
write("gltf", "light.gltf", doc(data_uri, light))
write("gltf", "sparse.gltf", doc(data_uri, sparse))
write("gltf", "strip.gltf", doc(data_uri, strip))


def glb(json_text, bin_data):
    j = json_text.encode()
    j += b" " * (-len(j) % 4)
    b = bin_data + b"\0" * (-len(bin_data) % 4)
    body = struct.pack("<I4s", len(j), b"JSON") + j + struct.pack("<I4s", len(b), b"BIN\0") + b
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


write("gltf", "tri.glb", glb(doc(None, glb=True), tri))
write("gltf", "light.glb", glb(doc(None, light, glb=True), tri))

# --- exr and compare: small uncompressed scanline OpenEXR files -----------------------
def exr(width, height, channels="BGR", half=False, value=0.25):
    """An uncompressed scanline OpenEXR image of `channels` (sorted, as the format wants),
    every sample `value`, in 16-bit (half) or 32-bit floats."""
    def attr(name, kind, data):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(data)) + data
    ptype = 1 if half else 2
    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", ptype, 0, 1, 1) for c in sorted(channels)) + b"\0"
    box = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = (attr("channels", "chlist", chlist) + attr("compression", "compression", b"\0")
              + attr("dataWindow", "box2i", box) + attr("displayWindow", "box2i", box)
              + attr("lineOrder", "lineOrder", b"\0") + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attr("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    start = 8 + len(header) + 8 * height
    sample = struct.pack("<e", value) if half else struct.pack("<f", value)
    line = sample * (width * len(channels))
    chunks, offsets = b"", b""
    for y in range(height):
        offsets += struct.pack("<Q", start + len(chunks))
        chunks += struct.pack("<ii", y, len(line)) + line
    return b"\x76\x2f\x31\x01" + struct.pack("<I", 2) + header + offsets + chunks


images = {
    "rgb-float-4x3.exr": exr(4, 3),
    "rgb-half-3x2.exr": exr(3, 2, half=True),
    "rgba-float-2x2.exr": exr(2, 2, "ABGR", value=1.5),
    "y-float-1x1.exr": exr(1, 1, "Y"),
}
for name, data in images.items():
    write("exr", name, data)
a, b = images["rgb-float-4x3.exr"], exr(4, 3, value=0.5)
write("compare", "same-size.bin", struct.pack("<I", len(a)) + a + b)
c = images["rgb-half-3x2.exr"]
write("compare", "other-size.bin", struct.pack("<I", len(a)) + a + c)

print("seeds written under", os.path.join(HERE, "corpus"))
