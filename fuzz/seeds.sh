#!/usr/bin/env bash
# Writes the seed corpus of every fuzz target into fuzz/corpus/TARGET/:
# the example scenes, a small OBJ and glTF/GLB, and the files of tiny views
# written by `sfp analytic --size 8` and `sfp render --size 8`.
# Usage: fuzz/seeds.sh [SFP_BINARY]   (default: `sfp` on the PATH)
set -euo pipefail
sfp=${1:-sfp}
here=$(cd "$(dirname "$0")" && pwd)
corpus=$here/corpus
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$corpus"/{scene_toml,obj,gltf,png,exr,meta_json}

cp "$here"/../scenes/examples/*.toml "$here"/../scenes/datasets/*.toml "$corpus/scene_toml/"

printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\nf 1/1 2/2 5/5\nf -1 -2 -3\n' \
    > "$corpus/obj/pyramid.obj"

# One triangle with normals, texture coordinates and u16 indices; the first
# byte of a gltf input picks JSON (even) or GLB (odd).
python3 - "$corpus/gltf" <<'PY'
import base64, json, struct, sys
out = sys.argv[1]
pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
nrm = struct.pack("<9f", 0, 0, 1, 0, 0, 1, 0, 0, 1)
uv = struct.pack("<6f", 0, 0, 1, 0, 0, 1)
idx = struct.pack("<3H", 0, 1, 2) + b"\0\0"
data = pos + nrm + uv + idx
views = [(0, 36), (36, 36), (72, 24), (96, 6)]
def doc(uri):
    buf = {"byteLength": len(data)}
    if uri is not None:
        buf["uri"] = uri
    return {
        "asset": {"version": "2.0"}, "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"children": [1], "translation": [0, 0, 1]}, {"mesh": 0, "scale": [2, 2, 2]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3}]}],
        "buffers": [buf],
        "bufferViews": [{"buffer": 0, "byteOffset": o, "byteLength": n} for o, n in views],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"},
        ],
    }
text = json.dumps(doc("data:application/octet-stream;base64," + base64.b64encode(data).decode()))
open(f"{out}/triangle.gltf", "wb").write(b"\0" + text.encode())
js = json.dumps(doc(None)).encode()
js += b" " * (-len(js) % 4)
glb = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js) + 8 + len(data))
glb += struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(data), b"BIN\0") + data
open(f"{out}/triangle.glb", "wb").write(b"\1" + glb)

# The same triangle with a 2×2 PNG as its base-colour, metallic-roughness
# and normal texture: embedded in the GLB's binary chunk, and as a data URI.
import zlib
def chunk(kind, body):
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 2, 0, 0, 0))
png += chunk(b"IDAT", zlib.compress(b"\0" + bytes(range(6)) + b"\0" + bytes(range(6, 12)))) + chunk(b"IEND", b"")
def textured(image):
    d = doc(None)
    d["meshes"][0]["primitives"][0]["material"] = 0
    d["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 0}}, "normalTexture": {"index": 0}}]
    d["textures"] = [{"source": 0}]
    d["images"] = [image]
    return d
d = textured({"uri": "data:image/png;base64," + base64.b64encode(png).decode()})
d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(data).decode()
open(f"{out}/textured.gltf", "wb").write(b"\0" + json.dumps(d).encode())
bin_ = data + png + b"\0" * (-len(png) % 4)
d = textured({"bufferView": len(views), "mimeType": "image/png"})
d["buffers"][0]["byteLength"] = len(bin_)
d["bufferViews"].append({"buffer": 0, "byteOffset": len(data), "byteLength": len(png)})
js = json.dumps(d).encode()
js += b" " * (-len(js) % 4)
glb = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js) + 8 + len(bin_))
glb += struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(bin_), b"BIN\0") + bin_
open(f"{out}/textured.glb", "wb").write(b"\1" + glb)
PY

"$sfp" analytic --size 8 --out "$tmp/analytic" > /dev/null
"$sfp" render "$here/../scenes/examples/sphere.toml" --size 8x8 --spp 1 --out "$tmp/render" > /dev/null
for view in analytic render; do
    for f in "$tmp/$view"/input/*.png; do cp "$f" "$corpus/png/$view-$(basename "$f")"; done
    for f in "$tmp/$view"/gt/*.exr; do cp "$f" "$corpus/exr/$view-$(basename "$f")"; done
    cp "$tmp/$view/meta.json" "$corpus/meta_json/$view.json"
done
ls "$corpus"/* | wc -l
