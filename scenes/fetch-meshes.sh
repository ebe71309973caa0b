#!/bin/bash
# Optional: fetches the full-resolution originals of the meshes the presets
# `a` and `b` ship decimated or repacked (scenes/meshes/) from their public
# sources into DEST (default: SFP_MESH_DIR), checking each file's SHA-256; a
# file already there with the right hash is kept. The presets render without
# them; with `export SFP_MESH_DIR=DEST` they read these instead. Sources,
# commits and licences: scenes/meshes.md.
#   scenes/fetch-meshes.sh [--from MIRROR] [DEST]
# --from copies from a local folder of the same layout instead (offline).
set -euo pipefail
FROM=""
if [ "${1:-}" = "--from" ]; then
    FROM="${2:?--from needs a folder}"
    shift 2
fi
DEST="${1:-${SFP_MESH_DIR:-}}"
if [ -z "$DEST" ]; then
    echo "usage: $0 [--from MIRROR] [DEST]   (DEST defaults to \$SFP_MESH_DIR)" >&2
    exit 2
fi
GH=https://raw.githubusercontent.com
JACOBSON=$GH/alecjacobson/common-3d-test-models/master/data
STEIN=$GH/odedstein/meshes
MUJOCO=$GH/google-deepmind/mujoco/46500072e8a86fda5b11573412c23a72f7743405/model/mug
POLYHAVEN=https://dl.polyhaven.org/file/ph-assets/Models/gltf/1k/Camera_01
# file in DEST | SHA-256 | source URL ("manual: where to get it" when none)
FILES="
teapot/teapot.obj|1b5396fedd74b577e32cef41146582c2f2e1a050d5b4915193c0ac1ad4187ed4|$JACOBSON/teapot.obj
duck/Duck.glb|65bf938f54d6073e619e76e007820bbf980cdc3dc0daec0d94830ffc4ae54ab5|$GH/KhronosGroup/glTF-Sample-Models/701733e16a88d571b75d4cc3e6255aa54d56e3b0/2.0/Duck/glTF-Binary/Duck.glb
camera/Camera_01_1k.gltf|9c5ca3104579c84ffcebdee5c6e5e09821fe8d4a5cd9ce95ed32d81507450ee3|$POLYHAVEN/Camera_01_1k.gltf
camera/Camera_01.bin|d3d2c78458a4823bc9821c2ba3994c95d15b044c7a1444ba089b163f74c3fcf2|$POLYHAVEN/Camera_01.bin
camera/textures/Camera_01_body_arm_1k.jpg|a3b1928d258fdb23687fb005a3d764b008475abb13b47a2bb87ed81200274635|$POLYHAVEN/textures/Camera_01_body_arm_1k.jpg
camera/textures/Camera_01_body_diff_1k.jpg|89b77ec525e933f9f2702e2ccb0c8ba32ecef31dac241bc034e3eddc9481f4f7|$POLYHAVEN/textures/Camera_01_body_diff_1k.jpg
camera/textures/Camera_01_body_nor_gl_1k.jpg|c7ec0d96ae9b5f16559069f1a4c9a006f3ec1d49a7707269a280fe23786db144|$POLYHAVEN/textures/Camera_01_body_nor_gl_1k.jpg
camera/textures/Camera_01_lens_body_arm_1k.jpg|6fef8a44334428a8f095315fa8043678994abcc671473cf43f7ca63ec10eb98f|$POLYHAVEN/textures/Camera_01_lens_body_arm_1k.jpg
camera/textures/Camera_01_lens_body_diff_1k.jpg|aafa05c5b106b960b21547ef9d4662083dfc7138261cbab1f10e143afe046b68|$POLYHAVEN/textures/Camera_01_lens_body_diff_1k.jpg
camera/textures/Camera_01_lens_body_nor_gl_1k.jpg|3d5e695a57ce38f0e35558f43f30497fff2f8cc844c903c95462d105b58cb333|$POLYHAVEN/textures/Camera_01_lens_body_nor_gl_1k.jpg
camera/textures/Camera_01_strap_arm_1k.jpg|17beca6e0542a1a28146b52cff06aad2e404541359e452deca83b74d01505c50|$POLYHAVEN/textures/Camera_01_strap_arm_1k.jpg
camera/textures/Camera_01_strap_diff_1k.jpg|3d4c9cb463b330b7ea4fc713f6dc90a0c5e6d9d3ba707b6921fe0a2d1f9ab146|$POLYHAVEN/textures/Camera_01_strap_diff_1k.jpg
camera/textures/Camera_01_strap_nor_gl_1k.jpg|5d4d99d5b1640d5a4d3c2227c264c232279773b5c92e4a6c50d2f34217880202|$POLYHAVEN/textures/Camera_01_strap_nor_gl_1k.jpg
human/human_man.obj|bad29482ce08f737912f544e3b1bef030a180e5e2efa211753a0b6a6606cab41|$STEIN/ea169fd4b17254b787d90dec077295c74f81780e/objects/human/human_man.obj
goathead/goathead.obj|b0aa414ce3c46e5e30ee506261f1e3cb85025e2a33b5b18bc638b08a7c57a6cb|$STEIN/e05bf12d2bee57a1b81a972f49140822726626ec/objects/goathead/goathead.obj
mug/mug.obj|656bfc987a038c90417ec98c671ab481e6a3ebe35a17d3b92e2ec0ee9593eb19|$MUJOCO/mug.obj
mug/mug.png|8bee0ad778cda4459b486a3fe97d49196d3583abf041020eb1a54ef840e95318|$MUJOCO/mug.png
"
hash_of() { sha256sum "$1" | cut -c1-64; }
failed=0
while IFS='|' read -r file sha source; do
    [ -n "$file" ] || continue
    target="$DEST/$file"
    if [ -f "$target" ] && [ "$(hash_of "$target")" = "$sha" ]; then
        echo "ok       $file (already there)"
        continue
    fi
    part="$DEST/.$(echo "$file" | tr / _).part"
    mkdir -p "$DEST"
    if [ -n "$FROM" ]; then
        cp "$FROM/$file" "$part" 2>/dev/null || { echo "missing  $file: not in $FROM" >&2; failed=$((failed + 1)); continue; }
    else
        code=0
        curl -fsSL --connect-timeout 10 -o "$part" "$source" || code=$?
        if [ "$code" -ne 0 ]; then
            rm -f "$part"
            # 6, 7, 28: no name resolution, no connection, timeout.
            if [ "$code" -eq 6 ] || [ "$code" -eq 7 ] || [ "$code" -eq 28 ]; then
                host="${source#*://}"
                echo "offline  cannot reach ${host%%/*} (curl exit $code): nothing more is tried; the presets render from the shipped meshes" >&2
                exit 1
            fi
            echo "failed   $file: cannot download $source (curl exit $code)" >&2
            failed=$((failed + 1))
            continue
        fi
    fi
    if [ "$(hash_of "$part")" != "$sha" ]; then
        echo "wrong    $file: its SHA-256 is not $sha (another version of the file?)" >&2
        rm -f "$part"
        failed=$((failed + 1))
        continue
    fi
    mkdir -p "$(dirname "$target")"
    mv "$part" "$target"
    echo "fetched  $file"
done <<<"$FILES"
if [ "$failed" -gt 0 ]; then
    echo "$failed files are missing or wrong in $DEST (see above); the presets still render from the shipped meshes" >&2
    exit 1
fi
echo "the full-resolution meshes are in $DEST; the presets read them after: export SFP_MESH_DIR=$DEST"
