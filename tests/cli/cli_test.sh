#!/usr/bin/env bash
# Usage: cli_test.sh DEFORMKIT SCRATCH_DIR
# Checks the CLI's contract: exit 0 on success, 2 with exactly one line on stderr for bad input or
# usage, outputs that exist and are readable.
set -u
dk=$1
work=$2
rm -rf "$work" && mkdir -p "$work"
failures=0
passed=0

expect() {  # expect NAME EXPECTED_RC CMD...
    local name=$1 want=$2; shift 2
    "$@" >"$work/out" 2>"$work/err"
    local rc=$?
    if [ "$rc" -ne "$want" ]; then
        echo "FAIL $name: exit $rc, expected $want"; cat "$work/err"; failures=$((failures + 1)); return 1
    fi
    if [ "$want" -eq 2 ] && [ "$(wc -l <"$work/err")" -ne 1 ]; then
        echo "FAIL $name: expected one line on stderr, got:"; cat "$work/err"; failures=$((failures + 1)); return 1
    fi
    passed=$((passed + 1))
}
contains() {  # contains NAME FILE TEXT
    if ! grep -qF -- "$3" "$2"; then
        echo "FAIL $1: '$3' not in $2:"; cat "$2"; failures=$((failures + 1)); return 1
    fi
    passed=$((passed + 1))
}

expect version 0 "$dk" --version
contains version "$work/out" "deformkit 0."
expect help 0 "$dk" preview --help
contains help "$work/out" "--texture"
expect no-subcommand 2 "$dk"
expect unknown-command 2 "$dk" nosuch
contains unknown-command "$work/err" "'nosuch' is not a command (expected one of: info, preview,"
expect unknown-farm-command 2 "$dk" farm nosuch
contains unknown-farm-command "$work/err" "'nosuch' is not a farm command (expected one of: plan, run, submit, report)"
expect unknown-option 2 "$dk" info --bogus x
# An empty path or value names nothing: refused naming the option, for every command.
expect empty-out 2 "$dk" eval "$work/none.json" --out ""
contains empty-out "$work/err" "usage error: --out: is empty (expected a value)"
expect empty-positional 2 "$dk" info ""
contains empty-positional "$work/err" "usage error: FILE: is empty (expected a value)"
expect missing-mesh 2 "$dk" info "$work/nope.obj"
contains missing-mesh "$work/err" "nope.obj"

# Meshes in other formats (assimp): a PLY reads; a file that is neither a mesh, a cache nor an image names them.
printf 'ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n' >"$work/quad.ply"
expect info-ply 0 "$dk" info "$work/quad.ply"
contains info-ply "$work/out" "faces       1 (triangles 0, quads 1, n-gons 0)"
echo "not a mesh" >"$work/notes.txt"
expect info-unknown 2 "$dk" info "$work/notes.txt"
contains info-unknown "$work/err" "is neither a mesh, a point cache nor an image (expected a mesh (.obj, .gltf, .glb, .fbx, .ply, .dae)"
# A file larger than the memory the process may have (a sparse 20 GB OBJ under a 4 GB limit) is exit 1,
# naming it, as any out-of-memory. (Not under AddressSanitizer, whose shadow memory the limit forbids.)
if ! grep -q __asan_init "$dk" && truncate -s 20G "$work/sparse.obj" 2>/dev/null; then
    expect info-too-large 1 bash -c "ulimit -v 4000000 && exec \"\$0\" info \"\$1\"" "$dk" "$work/sparse.obj"
    contains info-too-large "$work/err" "$work/sparse.obj: cannot be read into memory (21474836481 bytes) (expected the OBJ file to fit in this machine's memory)"
    rm -f "$work/sparse.obj"
fi
: >"$work/empty.exr"
expect info-empty 2 "$dk" info "$work/empty.exr"
contains info-empty "$work/err" "$work/empty.exr: is empty (0 bytes) (expected a mesh, a point cache or an image)"
# Images are read through DeformKit's OpenImageIO module, loaded on the first image read or write: a command
# on meshes alone never needs it; an image command without it names the image, the module and why.
expect image-module-unused 0 env DEFORMKIT_IMAGE_MODULE="$work/none/deformkit_image_oiio.so" "$dk" info "$work/quad.ply"
expect image-module-missing 2 env DEFORMKIT_IMAGE_MODULE="$work/none/deformkit_image_oiio.so" "$dk" info "$work/notes.txt"
contains image-module-missing "$work/err" "$work/notes.txt: cannot load DeformKit's image module ($work/none/deformkit_image_oiio.so: no such file) (expected deformkit_image_oiio.so installed beside the library (lib/deformkit) or named by DEFORMKIT_IMAGE_MODULE)"
expect image-module-not-a-library 2 env DEFORMKIT_IMAGE_MODULE="$work/quad.ply" "$dk" info "$work/notes.txt"
contains image-module-not-a-library "$work/err" "($work/quad.ply: invalid ELF header)"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n' >"$work/bad.obj"
expect bad-index 2 "$dk" info "$work/bad.obj"
contains bad-index "$work/err" "line 4"

expect demo 0 "$dk" demo --out "$work/demo" --resolution 64
for f in tube.obj rigidity.1001.exr rigidity.1002.exr mask.1001.exr mask.1002.exr albedo.1001.png albedo.1002.png preview.png; do
    if [ ! -s "$work/demo/$f" ]; then echo "FAIL demo: $f missing"; failures=$((failures + 1)); fi
done
for w in ffd ffd_frames taper twist bend wires wires_smooth mesh_warp; do
    for ext in obj png; do
        [ -s "$work/demo/warps/$w.$ext" ] || { echo "FAIL demo: warps/$w.$ext missing"; failures=$((failures + 1)); }
    done
done
[ -s "$work/demo/warps/beier_neely.png" ] || { echo "FAIL demo: warps/beier_neely.png missing"; failures=$((failures + 1)); }
for f in tube_slid.obj checker.1001.png checker.1002.png before.png after.png slide.png; do
    [ -s "$work/demo/slide/$f" ] || { echo "FAIL demo: slide/$f missing"; failures=$((failures + 1)); }
done
for f in uvwarp/report.html uvwarp/shot/uvwarp.jsonl uvwarp/shot/redirect.1001.0008.exr; do
    [ -s "$work/demo/$f" ] || { echo "FAIL demo: $f missing"; failures=$((failures + 1)); }
done
for f in tube.obj tube_slid.obj falloff.ptx before.png after.png ptex.png; do
    [ -s "$work/demo/ptex/$f" ] || { echo "FAIL demo: ptex/$f missing"; failures=$((failures + 1)); }
done
# docs/slide.md's commands remake the demo's slide pictures byte for byte.
for pair in "tube.obj before" "slide/tube_slid.obj after"; do
    set -- $pair
    expect "slide-preview-$2" 0 "$dk" preview "$work/demo/$1" --texture "$work/demo/slide/checker.<UDIM>.png" \
        --width 480 --height 480 --view -0.45,-0.3,-1 --out "$work/slide_$2.png"
    cmp -s "$work/slide_$2.png" "$work/demo/slide/$2.png" ||
        { echo "FAIL slide-preview-$2: differs from the demo's slide/$2.png"; failures=$((failures + 1)); }
done
# docs/slide.md's real-model and bent-limb pictures: its commands remake the committed images byte for byte
# (Spot's tail-dimple drag, with and without the fold limit; the slide after a bend in a scene).
repo="$(cd "$(dirname "$0")/../.." && pwd)"
spot="$repo/tests/data/spot/spot_quadrangulated.obj"
expect slide-spot 0 "$dk" slide "$spot" --handle 1858 --from 0,0,0 --to 0.0283,0.0717,-0.0088 --radius 0.2588 \
    --out "$work/spot_slid.obj"
contains slide-spot "$work/out" "moved 290, limited 0"
expect slide-spot-fold 0 "$dk" slide "$spot" --handle 1858 --from 0,0,0 --to 0.0283,0.0717,-0.0088 --radius 0.2588 \
    --fold-limit --out "$work/spot_fold_limit.obj"
contains slide-spot-fold "$work/out" "flipped triangles 0,"
# A glTF as pipelines hand it over (every triangle with its own vertices): the slide welds its split vertices.
expect slide-glb 0 "$dk" slide "$repo/tests/data/fox/Fox.glb" --handle 100 --from 0,0,0 --to 1,1,0 --radius 20 --out "$work/fox_slid.obj"
contains slide-glb "$work/out" "unreachable 0,"
contains slide-glb "$work/out" "1438 split vertices welded onto a coincident vertex"
mkdir -p "$work/examples"
sed 's|"../../demo-out/tube.obj"|"../demo/tube.obj"|' "$repo/docs/examples/slide_limb.json" >"$work/examples/slide_limb.json"
expect slide-limb 0 "$dk" eval "$work/examples/slide_limb.json" --out "$work/limb-out" --no-previews
for pair in "$spot spot_before" "$work/spot_slid.obj spot_after" "$work/spot_fold_limit.obj spot_fold_limit" \
    "$work/limb-out/limb.0001.obj limb_before" "$work/limb-out/limb.0002.obj limb_after"; do
    set -- $pair
    case $2 in
    spot*) view=(--frame -0.25,-0.35,0.8,0.3,0.2,1.1 --view 0,0,-1) ;;
    *) view=(--view -0.45,-0.3,-1) ;;
    esac
    expect "slide-picture-$2" 0 "$dk" preview "$1" --texture "$work/demo/slide/checker.<UDIM>.png" --width 400 \
        --height 400 "${view[@]}" --out "$work/$2.png"
    cmp -s "$work/$2.png" "$repo/docs/images/slide/$2.png" ||
        { echo "FAIL slide-picture-$2: differs from docs/images/slide/$2.png"; failures=$((failures + 1)); }
done
# A real UV layout with corners past its tile (Spot: six faces, up to 0.052 of a tile): info warns, and the UV
# warp takes the tile and says so once.
expect info-overhang 0 "$dk" info "$spot"
contains info-overhang "$work/out" "warning     6 faces overhang their UDIM tile, by up to 0.0522"
mkdir -p "$work/spotuv/out"
cp "$spot" "$work/spotuv/spot.0001.obj"
expect uvwarp-spot 0 "$dk" uvwarp --rest "$spot" --deformed "$work/spotuv/spot.####.obj" \
    --rigidity "$work/demo/rigidity.<UDIM>.exr" --frames 1 --out "$work/spotuv/out/redirect.<UDIM>.####.exr"
contains uvwarp-spot "$work/out" "tile 1001: 6 faces overhang the tile, by up to 0.0522"
# docs/ptex.md's commands remake the demo's Ptex pictures byte for byte, and each ptex subcommand runs.
for pair in "ptex/tube.obj before" "ptex/tube_slid.obj after"; do
    set -- $pair
    expect "ptex-preview-$2" 0 "$dk" preview "$work/demo/$1" --weights-ptex "$work/demo/ptex/falloff.ptx" \
        --width 480 --height 480 --view -0.45,-0.3,-1 --out "$work/ptex_$2.png"
    cmp -s "$work/ptex_$2.png" "$work/demo/ptex/$2.png" ||
        { echo "FAIL ptex-preview-$2: differs from the demo's ptex/$2.png"; failures=$((failures + 1)); }
done
expect ptex-info 0 "$dk" ptex info "$work/demo/ptex/falloff.ptx"
contains ptex-info "$work/out" "resolution  8x8: 23040 faces"
contains ptex-info "$work/out" "mesh data   yes"
expect ptex-to-vertex 0 "$dk" ptex to-vertex "$work/demo/ptex/falloff.ptx" "$work/demo/ptex/tube.obj" \
    --out "$work/falloff.json"
contains ptex-to-vertex "$work/out" "22242 vertex values"
expect ptex-slide 0 "$dk" slide "$work/demo/ptex/tube.obj" --handle 9627 --from 0,2,0 --to 0,2.3,0.4 \
    --radius 1.2 --weights-ptex "$work/demo/ptex/falloff.ptx" --out "$work/ptex_slid.obj"
expect ptex-slide-json 0 "$dk" slide "$work/demo/ptex/tube.obj" --handle 9627 --from 0,2,0 --to 0,2.3,0.4 \
    --radius 1.2 --weights "$work/falloff.json" --out "$work/json_slid.obj"
cmp -s "$work/ptex_slid.obj" "$work/json_slid.obj" ||
    { echo "FAIL ptex-slide: --weights-ptex and the to-vertex weights file differ"; failures=$((failures + 1)); }
expect ptex-from-vertex 0 "$dk" ptex from-vertex "$work/falloff.json" "$work/demo/ptex/tube.obj" \
    --out "$work/baked.ptx" --face-res 2
expect ptex-baked-info 0 "$dk" ptex info "$work/baked.ptx"
contains ptex-baked-info "$work/out" "2x2: 23040 faces"
expect ptex-from-udim 0 "$dk" ptex from-udim "$work/demo/albedo.<UDIM>.png" "$work/demo/tube.obj" \
    --out "$work/albedo.ptx" --face-res 4 --type u8
expect ptex-to-udim 0 "$dk" ptex to-udim "$work/albedo.ptx" "$work/demo/tube.obj" --out "$work/back.<UDIM>.png" \
    --resolution 64
[ -s "$work/back.1001.png" ] && [ -s "$work/back.1002.png" ] ||
    { echo "FAIL ptex-to-udim: tiles missing"; failures=$((failures + 1)); }
expect ptex-to-udim-coverage 0 "$dk" ptex to-udim "$work/albedo.ptx" "$work/demo/tube.obj" \
    --out "$work/cov.<UDIM>.exr" --resolution 64 --tiles 1001 --coverage
expect ptex-to-udim-coverage-info 0 "$dk" info "$work/cov.1001.exr"
contains ptex-to-udim-coverage-info "$work/out" "channels    4"  # the albedo's 3, and coverage
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n' >"$work/quad.obj"
expect ptex-wrong-mesh 2 "$dk" ptex to-vertex "$work/demo/ptex/falloff.ptx" "$work/quad.obj" --out "$work/x.json"
contains ptex-wrong-mesh "$work/err" "has 23040 faces"
# Errors that name the right thing: the mesh by its file (not the option or the Ptex file), a file once, a
# plain range, the mesh and face of a UV outside the UDIM tiles.
contains ptex-wrong-mesh "$work/err" "for mesh $work/quad.obj"
expect slide-ptex-wrong-mesh 2 "$dk" slide "$work/quad.obj" --handle 0 --from 0,0,0 --to 0.1,0,0 --radius 0.5 \
    --weights-ptex "$work/demo/ptex/falloff.ptx" --out "$work/x.obj"
contains slide-ptex-wrong-mesh "$work/err" "for mesh $work/quad.obj"
grep -q "for mesh --weights-ptex" "$work/err" && { echo "FAIL slide-ptex-wrong-mesh: names the option as the mesh"; failures=$((failures + 1)); }
head -c 200 "$work/demo/ptex/falloff.ptx" >"$work/trunc.ptx"
expect ptex-truncated 2 "$dk" ptex to-vertex "$work/trunc.ptx" "$work/demo/ptex/tube.obj" --out "$work/x.json"
[ "$(grep -o "trunc.ptx" "$work/err" | wc -l)" -eq 1 ] || { echo "FAIL ptex-truncated: the file is not named once:"; cat "$work/err"; failures=$((failures + 1)); }
expect slide-max-walk-0 2 "$dk" slide "$work/quad.obj" --handle 0 --from 0,0,0 --to 0.1,0,0 --radius 0.5 \
    --out "$work/x.obj" --max-walk 0
contains slide-max-walk-0 "$work/err" "--max-walk: is 0 (expected a number > 0)"
# A Ptex channel without a Ptex map is a usage error, not ignored.
expect slide-channel-alone 2 "$dk" slide "$work/quad.obj" --handle 0 --from 0,0,0 --to 0.1,0,0 --radius 0.5 \
    --out "$work/x.obj" --weights-channel 2
contains slide-channel-alone "$work/err" "--weights-channel requires --weights-ptex"
grep -q "e+308" "$work/err" && { echo "FAIL slide-max-walk-0: prints a range to 1.8e308"; failures=$((failures + 1)); }
# An output named as a file the command reads is refused before anything is written (a slid mesh over its
# rest mesh, a warped image over its source, a preview over its texture), symbolic links resolved.
cp "$work/quad.obj" "$work/quad-keep.obj"
expect slide-out-is-mesh 2 "$dk" slide "$work/quad.obj" --handle 0 --from 0,0,0 --to 0.1,0,0 --radius 0.5 --out "$work/quad.obj"
contains slide-out-is-mesh "$work/err" "$work/quad.obj: is the mesh, and the output (--out)"
cmp -s "$work/quad.obj" "$work/quad-keep.obj" || { echo "FAIL slide-out-is-mesh: the mesh was written"; failures=$((failures + 1)); }
ln -sf "$work/quad.obj" "$work/quad-link.obj"
expect slide-out-links-mesh 2 "$dk" slide "$work/quad.obj" --handle 0 --from 0,0,0 --to 0.1,0,0 --radius 0.5 --out "$work/quad-link.obj"
contains slide-out-links-mesh "$work/err" "is the mesh, and the output (--out)"
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt -0.45 0.1\nvt 0.05 0.1\nvt 0.05 0.9\nvt -0.45 0.9\nf 1/1 2/2 3/3 4/4\n' >"$work/left.obj"
printf '[0, 0.5, 1, 0.5]\n' >"$work/left.json"
expect ptex-left 0 "$dk" ptex from-vertex "$work/left.json" "$work/left.obj" --out "$work/left.ptx"
expect ptex-udim-tile 2 "$dk" ptex to-udim "$work/left.ptx" "$work/left.obj" --out "$work/l.<UDIM>.png" --tiles 1000
contains ptex-udim-tile "$work/err" "--tiles: '1000' is not a UDIM tile"
# A face that lies mostly off the tiles (u from -0.45 to 0.05) would lose that part: refused, as the UV warp
# refuses it, naming the face. One that overhangs its tile by up to a tenth (u from -0.05 to 0.45) belongs to
# it: its part inside is rendered.
expect ptex-udim-off-tiles 2 "$dk" ptex to-udim "$work/left.ptx" "$work/left.obj" --out "$work/l.<UDIM>.png" --resolution 16
contains ptex-udim-off-tiles "$work/err" "left.obj, UDIM tile 1001: face 0: overhangs the tile by 0.450000 (corner 0 at (-0.450000, 0.100000), off the UDIM tiles)"
sed 's/^vt -0.45 /vt -0.05 /; s/^vt 0.05 /vt 0.45 /' "$work/left.obj" >"$work/edge.obj"
expect ptex-udim-overhang 0 "$dk" ptex to-udim "$work/left.ptx" "$work/edge.obj" --out "$work/l.<UDIM>.png" --resolution 16
[ -s "$work/l.1001.png" ] || { echo "FAIL ptex-udim-overhang: tile missing"; failures=$((failures + 1)); }
# Two tiles, the second's folder missing: nothing is written (the first tile was, before).
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nvt 0.1 0.1\nvt 0.9 0.1\nvt 0.9 0.9\nvt 0.1 0.9\nvt 1.1 0.1\nvt 1.9 0.1\nvt 1.9 0.9\nvt 1.1 0.9\nf 1/1 2/2 3/3 4/4\nf 2/5 5/6 6/7 3/8\n' >"$work/two.obj"
printf '[0, 0.2, 0.4, 0.6, 0.8, 1]\n' >"$work/two.json"
expect ptex-two 0 "$dk" ptex from-vertex "$work/two.json" "$work/two.obj" --out "$work/two.ptx"
mkdir -p "$work/d1001"
expect ptex-udim-folder 2 "$dk" ptex to-udim "$work/two.ptx" "$work/two.obj" --out "$work/d<UDIM>/t.exr" --resolution 16
contains ptex-udim-folder "$work/err" "d1002/t.exr: cannot write: folder '$work/d1002' does not exist"
[ ! -e "$work/d1001/t.exr" ] || { echo "FAIL ptex-udim-folder: tile 1001 written"; failures=$((failures + 1)); }
# Faces without UVs beside faces with them (as exporters write them): read, in no tile, reported.
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nvt 0.1 0.1\nvt 0.9 0.1\nvt 0.9 0.9\nvt 0.1 0.9\nf 1/1 2/2 3/3 4/4\nf 2 5 3\n' >"$work/mixed.obj"
expect info-mixed-uvs 0 "$dk" info "$work/mixed.obj"
contains info-mixed-uvs "$work/out" "warning     1 face has no UVs (first on line 11): in no UDIM tile"
expect ptex-from-udim-mixed 0 "$dk" ptex from-udim "$work/demo/albedo.<UDIM>.png" "$work/mixed.obj" --out "$work/mixed.ptx"
contains ptex-from-udim-mixed "$work/out" "1 face has no UVs: written as 0"
expect ptex-udim-padding 2 "$dk" ptex to-udim "$work/left.ptx" "$work/left.obj" --out "$work/l.<UDIM>.png" --padding -1
contains ptex-udim-padding "$work/err" "usage error: --padding: is -1 (expected a number from 0 to 65536)"
printf 'not a ptex file, just some text that is long enough to hold a header of sixty-four bytes\n' >"$work/bad.ptx"
expect ptex-bad-file 2 "$dk" ptex info "$work/bad.ptx"
contains ptex-bad-file "$work/err" "bad.ptx"
expect ptex-bad-type 2 "$dk" ptex from-udim "$work/demo/albedo.<UDIM>.png" "$work/demo/tube.obj" \
    --out "$work/x.ptx" --type f64
expect info-mesh 0 "$dk" info "$work/demo/tube.obj"
contains info-mesh "$work/out" "vertices    22242"
contains info-mesh "$work/out" "UDIM tiles 1001 1002"
contains info-mesh "$work/out" "manifold    yes"
# The same inputs give the same bytes: a second demo run is identical file for file.
expect demo-again 0 "$dk" demo --out "$work/demo2" --resolution 64
for f in "$work"/demo/* "$work"/demo/warps/* "$work"/demo/slide/* "$work"/demo/ptex/*; do
    [ -f "$f" ] || continue
    if ! cmp -s "$f" "$work/demo2/${f#"$work"/demo/}"; then
        echo "FAIL determinism: $(basename "$f") differs between two demo runs"; failures=$((failures + 1))
    fi
done

# Non-manifold input is reported by info, not refused.
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n' >"$work/fin.obj"
expect info-nonmanifold 0 "$dk" info "$work/fin.obj"
contains info-nonmanifold "$work/out" "manifold    no (1 non-manifold edges"

expect info-image 0 "$dk" info "$work/demo/rigidity.1001.exr"
contains info-image "$work/out" "64 x 64"
contains info-image "$work/out" "half"
expect info-udim 0 "$dk" info "$work/demo/mask.<UDIM>.exr"
contains info-udim "$work/out" "tiles       2: 1001 1002"
expect info-udim-none 2 "$dk" info "$work/demo/nothing.<UDIM>.exr"

expect preview 0 "$dk" preview "$work/demo/tube.obj" --texture "$work/demo/albedo.<UDIM>.png" --out "$work/p.png" --width 200 --height 150 --edges
expect preview-size 0 "$dk" info "$work/p.png"
contains preview-size "$work/out" "200 x 150"
expect preview-bad-view 2 "$dk" preview "$work/demo/tube.obj" --view 1,2 --out "$work/q.png"
expect preview-zero-view 2 "$dk" preview "$work/demo/tube.obj" --view 0,0,0 --out "$work/q.png"
contains preview-zero-view "$work/err" "--view: '0,0,0' is not a direction (expected three finite numbers x,y,z, not all 0)"
expect preview-nan-view 2 "$dk" preview "$work/demo/tube.obj" --view nan,1,1 --out "$work/q.png"
# Out of memory (a 16384² picture under a 400 MB address-space limit): exit 1, a retry elsewhere may cure it.
expect out-of-memory 1 bash -c 'ulimit -v 400000; exec "$0" preview "$1" --out "$2" --width 16384 --height 16384' \
    "$dk" "$work/demo/tube.obj" "$work/huge.png"
contains out-of-memory "$work/err" "deformkit: error: out of memory"
expect preview-no-folder 2 "$dk" preview "$work/demo/tube.obj" --out "$work/missing/dir/q.png"

# Beier-Neely image warp: identical segment pairs leave the image as it is (bilinear at pixel centres).
printf '{"a": 1, "b": 2, "p": 0.5, "lines": [{"src": [[10, 10], [50, 12]], "dst": [[10, 10], [50, 12]]}]}' >"$work/same.json"
expect warp-identity 0 "$dk" warp "$work/demo/albedo.1001.png" --lines "$work/same.json" --out "$work/w.png"
if ! cmp -s "$work/demo/albedo.1001.png" "$work/w.png"; then
    # PNG encoders may differ in metadata; compare decoded pixels through info at least.
    expect warp-identity-info 0 "$dk" info "$work/w.png"
    contains warp-identity-info "$work/out" "64 x 64"
fi
printf '{"lines": [{"src": [[0, 0], [1, "x"]], "dst": [[0, 0], [1, 1]]}]}' >"$work/bad.json"
cp "$work/demo/albedo.1001.png" "$work/albedo-copy.png"
expect warp-out-is-image 2 "$dk" warp "$work/albedo-copy.png" --lines "$work/same.json" --out "$work/albedo-copy.png"
contains warp-out-is-image "$work/err" "$work/albedo-copy.png: is the image, and the output (--out)"
cmp -s "$work/albedo-copy.png" "$work/demo/albedo.1001.png" || { echo "FAIL warp-out-is-image: the image was written"; failures=$((failures + 1)); }
expect preview-out-is-texture 2 "$dk" preview "$work/demo/tube.obj" --texture "$work/albedo-copy.png" --out "$work/albedo-copy.png"
contains preview-out-is-texture "$work/err" "is the texture (--texture), and the picture (--out)"
expect warp-bad-json 2 "$dk" warp "$work/demo/albedo.1001.png" --lines "$work/bad.json" --out "$work/w2.png"
contains warp-bad-json "$work/err" "lines[0].src[1][1]"
[ ! -e "$work/w2.png" ] || { echo "FAIL warp-bad-json: output written"; failures=$((failures + 1)); }
expect warp-bad-variant 2 "$dk" warp "$work/demo/albedo.1001.png" --lines "$work/same.json" --out "$work/w3.png" --variant sideways

# Slide: an 11 x 11 grid of 0.1-unit quads at z = 0 with UVs and a group. Vertex (i, j) is number
# 11 j + i (0-based) at (0.1 i, 0.1 j, 0).
awk 'BEGIN {
    for (j = 0; j <= 10; j++) for (i = 0; i <= 10; i++) printf "v %g %g 0\n", i / 10, j / 10
    for (j = 0; j <= 10; j++) for (i = 0; i <= 10; i++) printf "vt %g %g\n", i / 10, j / 10
    print "g sheet"
    for (j = 0; j < 10; j++) for (i = 0; i < 10; i++) {
        a = 11 * j + i + 1
        printf "f %d/%d %d/%d %d/%d %d/%d\n", a, a, a + 1, a + 1, a + 12, a + 12, a + 11, a + 11
    }
}' >"$work/grid.obj"
expect slide 0 "$dk" slide "$work/grid.obj" --handle 60 --from 0,0,0 --to 0.1,0,0 --radius 0.3 --out "$work/slid.obj"
contains slide "$work/out" "wrote $work/slid.obj: moved "
contains slide "$work/out" "limited 0 (boundary-stopped 0, walk-limit-stopped 0), flipped triangles 0, unreachable 0, without a tangent plane 0, degenerate triangles 0"
[ "$(wc -l <"$work/out")" -eq 1 ] || { echo "FAIL slide: expected one summary line"; failures=$((failures + 1)); }
[ "$(grep -c '^vt ' "$work/slid.obj")" -eq 121 ] || { echo "FAIL slide-uvs: UVs not kept"; failures=$((failures + 1)); }
contains slide-group "$work/slid.obj" "g sheet"
# Closed form on a plane: vertex 61 at (0.6, 0.5) is 0.1 from the handle (0.5, 0.5), x = 1/3 of the
# radius, falloff 1 - 3x^2 + 2x^3 = 20/27: it moves to x = 0.6 + 0.1 * 20/27 (float positions: 1e-6).
awk -v want="$(awk 'BEGIN { printf "%.9f", 0.6 + 0.1 * 20 / 27 }')" '
    /^v / { n++; if (n == 62) { d = $2 - want; if (d < 0) d = -d; found = 1; e = $3 - 0.5; if (e < 0) e = -e; exit (d < 1e-6 && e < 1e-6 && $4 == 0) ? 0 : 1 } }
    END { if (!found) exit 1 }' "$work/slid.obj" && passed=$((passed + 1)) ||
    { echo "FAIL slide-closed-form: vertex 61 is not at x = 0.674074"; grep '^v ' "$work/slid.obj" | sed -n 62p; failures=$((failures + 1)); }
printf '[1, 1]' >"$work/short.json"
expect slide-bad-weights 2 "$dk" slide "$work/grid.obj" --handle 60 --from 0,0,0 --to 0.1,0,0 --radius 0.3 --weights "$work/short.json" --out "$work/s2.obj"
contains slide-bad-weights "$work/err" "has 2 weights"
expect slide-bad-handle 2 "$dk" slide "$work/grid.obj" --handle 500 --from 0,0,0 --to 0.1,0,0 --radius 0.3 --out "$work/s2.obj"
contains slide-bad-handle "$work/err" "vertex index out of range"
expect slide-bad-from 2 "$dk" slide "$work/grid.obj" --handle 60 --from 0,0 --to 0.1,0,0 --radius 0.3 --out "$work/s2.obj"
contains slide-bad-from "$work/err" "--from: '0,0' is not a point"
expect slide-bad-falloff 2 "$dk" slide "$work/grid.obj" --handle 60 --from 0,0,0 --to 0.1,0,0 --radius 0.3 --falloff 1,2 --out "$work/s2.obj"
contains slide-bad-falloff "$work/err" "--falloff"
expect slide-bad-region 2 "$dk" slide "$work/grid.obj" --handle 60 --from 0,0,0 --to 0.1,0,0 --radius 0.3 --region sphere --out "$work/s2.obj"
expect slide-missing-mesh 2 "$dk" slide "$work/nope.obj" --handle 0 --from 0,0,0 --to 0.1,0,0 --radius 0.3 --out "$work/s2.obj"
contains slide-missing-mesh "$work/err" "nope.obj"
[ ! -e "$work/s2.obj" ] || { echo "FAIL slide errors: output written"; failures=$((failures + 1)); }
expect slide-options 0 "$dk" slide "$work/grid.obj" --handle 60 --from 0,0,0 --to 0.1,0.05,0 --radius 0.3 --falloff 1,0.5,0 --envelope 0.5 --region geodesic --surface limit --max-walk 64 --out "$work/s3.obj"
# A drag of the whole radius folds the smooth falloff (it folds past r / 1.5): counted, and --fold-limit scales
# the drag to about 2/3 so nothing flips.
expect slide-folds 0 "$dk" slide "$work/grid.obj" --handle 60 --from 0,0,0 --to 0.3,0,0 --radius 0.3 --out "$work/s4.obj"
if grep -qF "flipped triangles 0," "$work/out"; then
    echo "FAIL slide-folds: no flipped triangle counted"; cat "$work/out"; failures=$((failures + 1))
fi
expect slide-fold-limit 0 "$dk" slide "$work/grid.obj" --handle 60 --from 0,0,0 --to 0.3,0,0 --radius 0.3 --fold-limit --out "$work/s4.obj"
contains slide-fold-limit "$work/out" "flipped triangles 0,"
contains slide-fold-limit "$work/out" "fold limit: drag scaled to 0.6"
# The paper's rule: a weight of 1 everywhere is the falloff, so vertex 61 moves the whole 0.1 (x = 0.7).
awk 'BEGIN { printf "["; for (i = 0; i < 121; i++) printf "%s1", (i ? ", " : ""); print "]" }' >"$work/ones.json"
expect slide-painted 0 "$dk" slide "$work/grid.obj" --handle 60 --from 0,0,0 --to 0.1,0,0 --radius 0.3 --weights "$work/ones.json" --painted-weights falloff --out "$work/s5.obj"
awk 'NR > 0 && /^v / { n++; if (n == 62) { d = $2 - 0.7; if (d < 0) d = -d; exit !(d < 1e-6) } }' "$work/s5.obj" ||
    { echo "FAIL slide-painted: vertex 61 is not at x = 0.7"; failures=$((failures + 1)); }
expect slide-bad-painted 2 "$dk" slide "$work/grid.obj" --handle 60 --from 0,0,0 --to 0.1,0,0 --radius 0.3 --painted-weights paper --out "$work/s5.obj"
contains slide-bad-painted "$work/err" "--painted-weights"

# UV warp over a 2-frame shot of the grid (UVs in tile 1001) with the demo's 64 x 64 rigidity map: frame 1 is the
# rest pose, frame 2 stretches 1.5x along x. The log's folder does not exist yet: it is made, as the outputs' are.
mkdir -p "$work/uv/out" "$work/uv/cold" "$work/uv/coldalone" "$work/uv/warm"
cp "$work/grid.obj" "$work/uv/anim.0001.obj"
awk '/^v / { printf "v %.9g %s %s\n", $2 * 1.5, $3, $4; next } { print }' "$work/grid.obj" >"$work/uv/anim.0002.obj"
uvwarp() { "$dk" uvwarp --rest "$work/grid.obj" --deformed "$work/uv/anim.####.obj" --rigidity "$work/demo/rigidity.<UDIM>.exr" "$@"; }
expect uvwarp 0 uvwarp --frames 1-2 --out "$work/uv/out/redirect.<UDIM>.####.exr" --texture "$work/demo/albedo.<UDIM>.png" \
    --bake "$work/uv/out/albedo.<UDIM>.####.png" --log "$work/uv/logs/log.jsonl"
contains uvwarp "$work/out" "uvwarp: tile 1001: 2 frames written (2 baked), 0 replayed, 0 skipped"
[ "$(wc -l <"$work/uv/logs/log.jsonl")" -eq 2 ] || { echo "FAIL uvwarp-log: expected 2 lines"; failures=$((failures + 1)); }
[ -s "$work/uv/out/albedo.1001.0002.png" ] || { echo "FAIL uvwarp: bake missing"; failures=$((failures + 1)); }
# A --mask that matches no tile's file (a typo) is refused before anything is written.
expect uvwarp-mask-typo 2 uvwarp --frames 1-2 --out "$work/uv/typo/redirect.<UDIM>.####.exr" --mask "$work/demo/msak.<UDIM>.exr"
contains uvwarp-mask-typo "$work/err" "msak.<UDIM>.exr: matches no file for any of the mesh's tiles"
[ ! -e "$work/uv/typo" ] || { echo "FAIL uvwarp-mask-typo: output folder created"; failures=$((failures + 1)); }
# Storage that fails while writing (a full disk, here /dev/full) is exit 1, not bad input: so is standard
# output that cannot be written (a farm task's log, a listing redirected to a full disk).
if [ -w /dev/full ]; then
    expect uvwarp-log-full 1 uvwarp --frames 1-2 --out "$work/uv/full/redirect.<UDIM>.####.exr" --log /dev/full
    contains uvwarp-log-full "$work/err" "/dev/full: cannot write the log (expected enough space to write)"
    "$dk" deformers --markdown >/dev/full 2>"$work/err"
    [ $? -eq 1 ] && grep -qF "standard output: cannot write" "$work/err" && passed=$((passed + 1)) ||
        { echo "FAIL stdout-full: expected exit 1 naming standard output"; cat "$work/err"; failures=$((failures + 1)); }
fi
# The shot's page: from the run (--report), and from logs merged with a broken one (its file and line in the
# page, exit 0); no log at all is exit 2.
expect uvwarp-report 0 uvwarp --frames 1-2 --out "$work/uv/rep/redirect.<UDIM>.####.exr" --report "$work/uv/rep/report.html"
contains uvwarp-report "$work/out" "uvwarp: report $work/uv/rep/report.html"
contains uvwarp-report "$work/uv/rep/report.html" "measured again from its files: the same"
contains uvwarp-report "$work/uv/rep/report.html" 'data-tile="1001" data-written="2"'
printf '{"tile":1001,"frame":3,"status":"written"}\n{"tile":1001,"frame":4,"sta' >"$work/uv/broken.jsonl"
expect report 0 "$dk" report "$work/uv/logs/log.jsonl" "$work/uv/broken.jsonl" --out "$work/uv/report.html"
contains report "$work/out" "report: wrote $work/uv/report.html (2 log lines, 8 pictures beside it; 2 problems)"
contains report "$work/uv/report.html" "broken.jsonl:1: is a written frame without metrics.rigid_stretch_removed"
contains report "$work/uv/report.html" "broken.jsonl:2: is not JSON"
contains report "$work/uv/report.html" "deformkit uvwarp --rest $work/grid.obj"
expect report-no-log 2 "$dk" report
contains report-no-log "$work/err" "report: has no log to read"
expect uvwarp-info 0 "$dk" info "$work/uv/out/redirect.1001.0002.exr"
contains uvwarp-info "$work/out" "64 x 64"
contains uvwarp-info "$work/out" "channels    2"
contains uvwarp-info "$work/out" "type        float"
contains uvwarp-info "$work/out" "deformkit:uvwarp:frame = 2"
# info reads far enough to know an image is whole: a truncated EXR is exit 2 naming it, nothing printed.
head -c "$(($(wc -c <"$work/uv/out/redirect.1001.0002.exr") / 2))" "$work/uv/out/redirect.1001.0002.exr" >"$work/trunc.exr"
expect info-truncated-exr 2 "$dk" info "$work/trunc.exr"
contains info-truncated-exr "$work/err" "trunc.exr"
[ ! -s "$work/out" ] || { echo "FAIL info-truncated-exr: printed a header"; cat "$work/out"; failures=$((failures + 1)); }
expect uvwarp-resume 0 uvwarp --frames 1-2 --out "$work/uv/out/redirect.<UDIM>.####.exr"
contains uvwarp-resume "$work/out" "0 frames written, 0 replayed, 2 skipped"
# Each frame from the identity (the default of a shot): frame 2 alone gives frame 2 of the whole shot, byte
# for byte, and the header says so; warm-started (--warm-start) it does not.
expect uvwarp-cold 0 uvwarp --frames 1-2 --out "$work/uv/cold/redirect.<UDIM>.####.exr"
expect uvwarp-cold-alone 0 uvwarp --frames 2-2 --out "$work/uv/coldalone/redirect.<UDIM>.####.exr"
cmp -s "$work/uv/cold/redirect.1001.0002.exr" "$work/uv/coldalone/redirect.1001.0002.exr" ||
    { echo "FAIL uvwarp-cold-alone: frame 2 alone differs from frame 2 of the shot"; failures=$((failures + 1)); }
expect uvwarp-cold-info 0 "$dk" info "$work/uv/cold/redirect.1001.0002.exr"
contains uvwarp-cold-info "$work/out" '"warmStart":false'
expect uvwarp-warm 0 uvwarp --frames 1-2 --warm-start --out "$work/uv/warm/redirect.<UDIM>.####.exr"
cmp -s "$work/uv/warm/redirect.1001.0002.exr" "$work/uv/coldalone/redirect.1001.0002.exr" &&
    { echo "FAIL uvwarp-warm: a warm-started frame 2 equals frame 2 alone"; failures=$((failures + 1)); }
expect uvwarp-warm-info 0 "$dk" info "$work/uv/warm/redirect.1001.0002.exr"
contains uvwarp-warm-info "$work/out" '"warmStart":true'
# The live presets' over-relaxation of the coarse levels: recorded in the header, and in range [1, 2].
expect uvwarp-relaxed 0 uvwarp --frames 1-1 --warm-start --iterations 1 --sweeps-per-level 1,2,10 --coarse-relaxation 1.4 --max-levels 3 --cold-iterations 2 --out "$work/uv/relaxed/redirect.<UDIM>.####.exr"
expect uvwarp-relaxed-info 0 "$dk" info "$work/uv/relaxed/redirect.1001.0001.exr"
contains uvwarp-relaxed-info "$work/out" '"coarseRelaxation":1.4'
contains uvwarp-relaxed-info "$work/out" '"maxLevels":3'
contains uvwarp-relaxed-info "$work/out" '"coldIterations":2'
expect uvwarp-relaxation-range 2 uvwarp --frames 1-1 --coarse-relaxation 2.5 --out "$work/uv/out/x.<UDIM>.####.exr"
contains uvwarp-relaxation-range "$work/err" "coarse-relaxation"
# The older option names still work and record the declared names; zero iterations or no sweeps at all are
# refused, naming the option as the command spells it.
expect uvwarp-aliases 0 uvwarp --frames 1-1 --sweeps 2,3 --border-width 2 --out "$work/uv/aliases/redirect.<UDIM>.####.exr"
expect uvwarp-aliases-info 0 "$dk" info "$work/uv/aliases/redirect.1001.0001.exr"
contains uvwarp-aliases-info "$work/out" '"sweepsPerLevel":[2,3]'
contains uvwarp-aliases-info "$work/out" '"maskBorderWidth":2'
expect uvwarp-zero-iterations 2 uvwarp --frames 1-1 --iterations 0 --out "$work/uv/out/x.<UDIM>.####.exr"
contains uvwarp-zero-iterations "$work/err" "--iterations: is 0 (expected a whole number from 1 to 100000)"
expect uvwarp-zero-sweeps 2 uvwarp --frames 1-1 --sweeps-per-level 0,0 --out "$work/uv/out/x.<UDIM>.####.exr"
contains uvwarp-zero-sweeps "$work/err" "--sweeps-per-level: is [0, 0]"
expect uvwarp-new-folder 0 uvwarp --frames 1-1 --out "$work/uv/made/here/redirect.<UDIM>.####.exr"
[ -s "$work/uv/made/here/redirect.1001.0001.exr" ] || { echo "FAIL uvwarp-new-folder: map missing"; failures=$((failures + 1)); }
# Outputs never destroy what they replace: an extension that is not the format's, a FIFO, a path in a file.
expect slide-out-png 2 "$dk" slide "$work/grid.obj" --handle 0 --from 0,0,0 --to 0.1,0,0 --radius 0.5 --out "$work/o.png"
contains slide-out-png "$work/err" "ending in .obj"
[ ! -e "$work/o.png" ] || { echo "FAIL slide-out-png: o.png written"; failures=$((failures + 1)); }
mkfifo "$work/pipe.obj"
expect slide-out-fifo 2 "$dk" slide "$work/grid.obj" --handle 0 --from 0,0,0 --to 0.1,0,0 --radius 0.5 --out "$work/pipe.obj"
contains slide-out-fifo "$work/err" "is a FIFO"
[ -p "$work/pipe.obj" ] || { echo "FAIL slide-out-fifo: the FIFO was replaced"; failures=$((failures + 1)); }
printf 'x' >"$work/afile"
expect slide-out-in-file 2 "$dk" slide "$work/grid.obj" --handle 0 --from 0,0,0 --to 0.1,0,0 --radius 0.5 --out "$work/afile/o.obj"
contains slide-out-in-file "$work/err" "afile' is a file, not a folder"
ln -s "$work/grid.obj" "$work/linked.obj"
cp "$work/grid.obj" "$work/grid_before.obj"
expect slide-out-link 0 "$dk" slide "$work/grid_before.obj" --handle 0 --from 0,0,0 --to 0.1,0,0 --radius 0.5 --out "$work/linked.obj"
[ -L "$work/linked.obj" ] || { echo "FAIL slide-out-link: the link was replaced"; failures=$((failures + 1)); }
cmp -s "$work/grid.obj" "$work/grid_before.obj" && { echo "FAIL slide-out-link: the link's target is unchanged"; failures=$((failures + 1)); }
cp "$work/grid_before.obj" "$work/grid.obj"
expect uvwarp-no-out 2 uvwarp --frames 1-2
expect uvwarp-bake-alone 2 uvwarp --frames 1-2 --out "$work/uv/out/r.<UDIM>.####.exr" --bake "$work/uv/out/b.<UDIM>.####.png"
expect uvwarp-bad-frames 2 uvwarp --frames 2-1 --out "$work/uv/out/r.<UDIM>.####.exr"
contains uvwarp-bad-frames "$work/err" "--frames"
expect uvwarp-resolution 2 uvwarp --frames 1-2 --resolution 48 --out "$work/uv/out/r.<UDIM>.####.exr"
contains uvwarp-resolution "$work/err" "--resolution: is 48"
expect uvwarp-missing-frame 2 uvwarp --frames 1-3 --out "$work/uv/out/r.<UDIM>.####.exr"
contains uvwarp-missing-frame "$work/err" "anim.0003.obj: frame 3: is missing"
[ ! -e "$work/uv/out/r.1001.0001.exr" ] || { echo "FAIL uvwarp errors: output written"; failures=$((failures + 1)); }

# uvwarp with an orientation map (the demo's mask: 0 or 1 per texel), then one of the wrong size.
expect uvwarp-orientation 0 uvwarp --frames 1-2 --orientation "$work/demo/mask.<UDIM>.exr" --out "$work/uv/out/o.<UDIM>.####.exr"
[ -s "$work/uv/out/o.1001.0002.exr" ] || { echo "FAIL uvwarp-orientation: output missing"; failures=$((failures + 1)); }
cp "$work/p.png" "$work/orient_bad.1001.png"  # 200 x 150: not the rigidity map's size
expect uvwarp-orientation-size 2 uvwarp --frames 1-2 --orientation "$work/orient_bad.<UDIM>.png" --out "$work/uv/out/o2.<UDIM>.####.exr"
contains uvwarp-orientation-size "$work/err" "orientation map"

# eval: a scene with one twisted grid over two frames, then a scene with a misspelled parameter.
cat >"$work/shot.json" <<JSON
{"deformkit_scene": 1, "frames": [1, 2],
 "objects": [{"name": "grid", "mesh": "grid.obj",
   "stack": [{"type": "twist", "params": {"handleY": [0, 0, 1],
     "endAngle": {"keys": [{"frame": 1, "value": 0}, {"frame": 2, "value": 0.5, "interpolation": "linear"}]}}}]}]}
JSON
expect eval 0 "$dk" eval "$work/shot.json" --out "$work/eval"
[ -s "$work/eval/grid.0001.obj" ] && [ -s "$work/eval/grid.0002.obj" ] || { echo "FAIL eval: outputs missing"; failures=$((failures + 1)); }
sed 's/endAngle/endAngel/' "$work/shot.json" >"$work/bad_shot.json"
expect eval-bad-param 2 "$dk" eval "$work/bad_shot.json" --out "$work/eval-bad"
contains eval-bad-param "$work/err" "objects[0].stack[0].params.endAngel"
[ ! -e "$work/eval-bad" ] || { echo "FAIL eval-bad-param: output folder created"; failures=$((failures + 1)); }
# An empty --frames (a wrapper's unset variable) is refused, not the whole shot; frames beyond +-1e9 are
# refused by every command, so a plan never holds frames its tasks refuse (a range up to 2^31 - 1 never ended).
expect eval-empty-frames 2 "$dk" eval "$work/shot.json" --frames "" --out "$work/eval-empty"
contains eval-empty-frames "$work/err" "--frames: '' is not a frame"
[ ! -e "$work/eval-empty" ] || { echo "FAIL eval-empty-frames: output folder created"; failures=$((failures + 1)); }
expect farm-plan-empty-frames 2 "$dk" farm plan "$work/shot.json" --frames "" --out "$work/plan-empty"
expect farm-plan-top-frame 2 timeout 20 "$dk" farm plan "$work/shot.json" --frames 2147483646-2147483647 --out "$work/plan-top"
contains farm-plan-top-frame "$work/err" "out of range (expected frames from -1000000000 to 1000000000)"
# The shot as a point cache instead of OBJs, fed back to uvwarp as its deformed frames; bad caches are exit 2
# naming the file and the frame.
expect eval-pc2 0 "$dk" eval "$work/shot.json" --out "$work/eval-pc2" --no-previews --cache pc2 --no-objs
contains eval-pc2 "$work/out" "point cache"
[ "$(ls "$work/eval-pc2")" = "grid.pc2" ] || { echo "FAIL eval-pc2: expected grid.pc2 alone"; failures=$((failures + 1)); }
[ "$(stat -c %s "$work/eval-pc2/grid.pc2")" -eq $((32 + 2 * 121 * 12)) ] || { echo "FAIL eval-pc2: size"; failures=$((failures + 1)); }
expect info-pc2 0 "$dk" info "$work/eval-pc2/grid.pc2"
contains info-pc2 "$work/out" "frames      1-2 (2 whole frames)"
expect uvwarp-pc2 0 "$dk" uvwarp --rest "$work/grid.obj" --deformed "$work/eval-pc2/grid.pc2" --frames 1-2 \
    --rigidity "$work/demo/rigidity.<UDIM>.exr" --out "$work/uv-pc2/redirect.<UDIM>.####.exr" --report "$work/uv-pc2/report.html"
contains uvwarp-pc2 "$work/out" "2 frames written"
# The page reads the worst frame's positions from the cache the header names ("grid.pc2 frame N").
contains uvwarp-pc2 "$work/uv-pc2/report.html" "measured again from its files: the same"
expect uvwarp-pc2-frame 2 "$dk" uvwarp --rest "$work/grid.obj" --deformed "$work/eval-pc2/grid.pc2" --frames 1-3 \
    --rigidity "$work/demo/rigidity.<UDIM>.exr" --out "$work/uv-pc2/redirect.<UDIM>.####.exr"
contains uvwarp-pc2-frame "$work/err" "grid.pc2: frame 3: is not in the cache"
head -c 1000 "$work/eval-pc2/grid.pc2" >"$work/cut.pc2"
expect uvwarp-pc2-cut 2 "$dk" uvwarp --rest "$work/grid.obj" --deformed "$work/cut.pc2" --frames 1-2 \
    --rigidity "$work/demo/rigidity.<UDIM>.exr" --out "$work/uv-pc2/redirect.<UDIM>.####.exr"
contains uvwarp-pc2-cut "$work/err" "cut.pc2: frame 1: is cut short"
# A rest position beyond the solver's range is the rest mesh's fault, not the cache's vertex order.
awk 'BEGIN { done = 0 } /^v / && !done { print "v 1e20 0 0"; done = 1; next } { print }' "$work/grid.obj" >"$work/grid-far.obj"
expect uvwarp-rest-far 2 "$dk" uvwarp --rest "$work/grid-far.obj" --deformed "$work/eval-pc2/grid.pc2" --frames 1-2 \
    --rigidity "$work/demo/rigidity.<UDIM>.exr" --out "$work/uv-far/redirect.<UDIM>.####.exr"
contains uvwarp-rest-far "$work/err" "grid-far.obj: vertex 0: is (1e+20, 0, 0) (expected finite coordinates within +-1e15"

# eval with the UV warp as the scene's last stage, then a farm plan of frame-range x tile tasks.
cat >"$work/uvshot.json" <<JSON
{"deformkit_scene": 1, "frames": [1, 2],
 "objects": [{"name": "grid", "mesh": "grid.obj",
   "stack": [{"type": "taper", "params": {"handleY": [1, 0, 0], "endScale": 1.4}},
             {"type": "uvwarp", "rigidity": "demo/rigidity.<UDIM>.exr", "params": {"iterations": 4}}]}]}
JSON
expect eval-uvwarp 0 "$dk" eval "$work/uvshot.json" --out "$work/eval-uv" --no-previews
contains eval-uvwarp "$work/out" "grid uvwarp tile 1001: 2 frames written"
# A mask or texture pattern that matches no file (a typo) is named by its JSON path.
for key in mask texture; do
    sed "s|\"params\": {\"iterations\": 4}|\"$key\": \"demo/typo.<UDIM>.exr\"|" "$work/uvshot.json" >"$work/uvtypo.json"
    expect eval-uvwarp-$key-typo 2 "$dk" eval "$work/uvtypo.json" --out "$work/eval-uv-typo" --no-previews
    contains eval-uvwarp-$key-typo "$work/err" "uvtypo.json: objects[0].stack[1].$key: $work/demo/typo.<UDIM>.exr: matches no file for any of the mesh's tiles"
done
expect eval-uvwarp-report 0 "$dk" eval "$work/uvshot.json" --out "$work/eval-uv-r" --no-previews --report "$work/eval-uv-r/shot.html"
contains eval-uvwarp-report "$work/out" "eval: report $work/eval-uv-r/shot.html written"
contains eval-uvwarp-report "$work/eval-uv-r/uvwarp.jsonl" '"object":"grid"'
contains eval-uvwarp-report "$work/eval-uv-r/shot.html" "measured again from its files: the same"
contains eval-uvwarp-report "$work/eval-uv-r/shot.html" "deformkit eval $work/uvshot.json --frames 1-2"
# A report named as the scene, or as one of eval's own outputs, is refused before anything is written.
cp "$work/uvshot.json" "$work/uvshot-keep.json"
expect eval-report-scene 2 "$dk" eval "$work/uvshot.json" --out "$work/eval-uv-s" --no-previews --report "$work/uvshot.json"
contains eval-report-scene "$work/err" "$work/uvshot.json: is the scene, and the report (--report)"
cmp -s "$work/uvshot.json" "$work/uvshot-keep.json" || { echo "FAIL eval-report-scene: the scene was written"; failures=$((failures + 1)); }
[ -e "$work/eval-uv-s" ] && { echo "FAIL eval-report-scene: the output folder was made"; failures=$((failures + 1)); }
expect eval-report-log 2 "$dk" eval "$work/uvshot.json" --out "$work/eval-uv-s" --no-previews --report "$work/eval-uv-s/uvwarp.jsonl"
contains eval-report-log "$work/err" "is both the UV-warp stages' log and the report (--report)"
# Written as a point cache alone (no per-frame OBJ): the page's heatmaps come from the scene itself.
expect eval-uvwarp-report-cache 0 "$dk" eval "$work/uvshot.json" --out "$work/eval-uv-c" --no-previews --cache pc2 --no-objs \
    --report "$work/eval-uv-c/shot.html"
contains eval-uvwarp-report-cache "$work/eval-uv-c/shot.html" "measured again from its files: the same"
expect report-scene 0 "$dk" report "$work/eval-uv-c/uvwarp.jsonl" --scene "$work/uvshot.json" --out "$work/eval-uv-c/again.html"
contains report-scene "$work/eval-uv-c/again.html" "measured again from its files: the same"
expect report-no-scene 0 "$dk" report "$work/eval-uv-c/uvwarp.jsonl" --out "$work/eval-uv-c/bare.html"
contains report-no-scene "$work/out" "grid tile 1001: no heatmaps: the deformed mesh 'grid.000"
# Nor is a page written over a map its log names (a rerun would skip the map as done).
cp "$work/eval-uv-c/grid.redirect.1001.0002.exr" "$work/map-c.exr"
expect report-over-map 2 "$dk" report "$work/eval-uv-c/uvwarp.jsonl" --out "$work/eval-uv-c/grid.redirect.1001.0002.exr"
contains report-over-map "$work/err" "grid.redirect.1001.0002.exr: is an output the log"
cmp -s "$work/eval-uv-c/grid.redirect.1001.0002.exr" "$work/map-c.exr" ||
    { echo "FAIL report-over-map: the map was written over"; failures=$((failures + 1)); }
expect eval-uvwarp-info 0 "$dk" info "$work/eval-uv/grid.redirect.1001.0002.exr"
contains eval-uvwarp-info "$work/out" "deformkit:uvwarp:frame = 2"
expect farm-plan-tiles 0 "$dk" farm plan "$work/uvshot.json" --chunk 1 --tiles-per-task 1 --out "$work/farm-uv"
contains farm-plan-tiles "$work/farm-uv/farm_plan.json" '"tiles":[1001]'
expect farm-run-tiles 0 "$dk" farm run "$work/farm-uv/farm_plan.json" --task 3
contains farm-run-tiles "$work/farm-uv/farm_plan.json" '"warmUp": 6'
# The farm's page from the tasks' logs as Slurm names them: the mesh tasks 0 and 1 and task 2 (frame 1's
# map) have not run yet, then task 2 runs and its log also holds an error line.
cp "$work/out" "$work/farm-uv/farm_plan.77_3.log"
expect farm-report-missing 0 "$dk" farm report "$work/farm-uv/farm_plan.json"
contains farm-report-missing "$work/out" "farm: report $work/farm-uv/report.html (1 log lines, 3 problems)"
contains farm-report-missing "$work/farm-uv/report.html" 'data-task="0">task 0 (frames 1–1, meshes): no log line'
contains farm-report-missing "$work/farm-uv/report.html" 'data-task="2">task 2 (frames 1–1, tiles 1001): no log line'
contains farm-report-missing "$work/farm-uv/report.html" "deformkit farm run $work/farm-uv/farm_plan.json --task 2"
"$dk" farm run "$work/farm-uv/farm_plan.json" --task 2 >"$work/farm-uv/farm_plan.77_2.log" 2>&1
echo "deformkit: error: an earlier attempt failed" >>"$work/farm-uv/farm_plan.77_2.log"
expect farm-report 0 "$dk" report --plan "$work/farm-uv/farm_plan.json"
contains farm-report "$work/out" "(2 log lines, 8 pictures beside it; 3 problems)"
contains farm-report "$work/farm-uv/report.html" "farm_plan.77_2.log:2: is not JSON: 'deformkit: error: an earlier attempt failed'"
# The page is written over none of the plan's outputs and none of the logs it reads.
cp "$work/farm-uv/grid.redirect.1001.0002.exr" "$work/map-before.exr"
expect farm-report-over-map 2 "$dk" farm report "$work/farm-uv/farm_plan.json" --out "$work/farm-uv/grid.redirect.1001.0002.exr"
contains farm-report-over-map "$work/err" "grid.redirect.1001.0002.exr: is an output of task 3 of the plan (expected a page apart"
cmp -s "$work/farm-uv/grid.redirect.1001.0002.exr" "$work/map-before.exr" ||
    { echo "FAIL farm-report-over-map: the map was written over"; failures=$((failures + 1)); }
expect farm-report-over-log 2 "$dk" farm report "$work/farm-uv/farm_plan.json" --out "$work/farm-uv/farm_plan.77_2.log"
contains farm-report-over-log "$work/err" "farm_plan.77_2.log: is a log the page reads"
# Each frame from the identity (a scene's default): the task of frame 2 writes eval's bytes, warmed up or not.
cmp -s "$work/farm-uv/grid.redirect.1001.0002.exr" "$work/eval-uv/grid.redirect.1001.0002.exr" ||
    { echo "FAIL farm-run-tiles: the task of frame 2 should write eval's frame 2"; failures=$((failures + 1)); }
expect farm-plan-cold 0 "$dk" farm plan "$work/uvshot.json" --chunk 1 --warm-up 0 --out "$work/farm-uv-cold"
expect farm-run-cold 0 "$dk" farm run "$work/farm-uv-cold/farm_plan.json" --task 3
cmp -s "$work/farm-uv-cold/grid.redirect.1001.0002.exr" "$work/eval-uv/grid.redirect.1001.0002.exr" ||
    { echo "FAIL farm-run-cold: without warm-up the task of frame 2 should write eval's frame 2"; failures=$((failures + 1)); }
# Warm-started ("warmStart": true): without warm-up the task of frame 2 starts cold and differs from eval's.
sed 's/"iterations": 4}/"iterations": 4, "warmStart": true}/' "$work/uvshot.json" >"$work/uvshot_warm.json"
expect eval-uvwarp-warm 0 "$dk" eval "$work/uvshot_warm.json" --out "$work/eval-uv-warm" --no-previews
expect farm-plan-warm 0 "$dk" farm plan "$work/uvshot_warm.json" --chunk 1 --warm-up 0 --out "$work/farm-uv-warm"
expect farm-run-warm 0 "$dk" farm run "$work/farm-uv-warm/farm_plan.json" --task 3
cmp -s "$work/farm-uv-warm/grid.redirect.1001.0002.exr" "$work/eval-uv-warm/grid.redirect.1001.0002.exr" &&
    { echo "FAIL farm-run-warm: a cold start at frame 2 should differ from eval's warm start"; failures=$((failures + 1)); }
[ -s "$work/farm-uv-warm/grid.redirect.1001.0002.exr" ] || { echo "FAIL farm-run-warm: output missing"; failures=$((failures + 1)); }
# Out of memory in a task (a 16384-cell grid under a 1.5 GB address-space limit): the CLI's message, exit 1.
sed 's/"params": {"iterations": 4}/"resolution": 16384, "params": {"iterations": 4}/' "$work/uvshot.json" >"$work/uvshot_huge.json"
expect farm-plan-huge 0 "$dk" farm plan "$work/uvshot_huge.json" --chunk 1 --frames 1 --warm-up 0 --out "$work/farm-uv-huge"
expect farm-run-out-of-memory 1 bash -c 'ulimit -v 1500000; exec "$0" farm run "$1" --task 1' \
    "$dk" "$work/farm-uv-huge/farm_plan.json"
contains farm-run-out-of-memory "$work/err" "deformkit: error: out of memory"
expect farm-plan-bad-warm-up 2 "$dk" farm plan "$work/uvshot.json" --warm-up -1 --out "$work/farm-uv3"
contains farm-plan-bad-warm-up "$work/err" "--warm-up: is -1"
expect farm-plan-bad-tiles 2 "$dk" farm plan "$work/uvshot.json" --tiles-per-task 0 --out "$work/farm-uv2"
contains farm-plan-bad-tiles "$work/err" "--tiles-per-task: is 0"
sed 's/"iterations": 4/"iterations": 0/' "$work/uvshot.json" >"$work/uvshot_bad.json"
expect eval-uvwarp-bad 2 "$dk" eval "$work/uvshot_bad.json" --out "$work/eval-uv-bad"
contains eval-uvwarp-bad "$work/err" "objects[0].stack[1].params.iterations: is 0"

# A truncated image is a clear error, not a crash.
head -c 300 "$work/demo/albedo.1001.png" >"$work/trunc.png"
expect truncated-texture 2 "$dk" preview "$work/demo/tube.obj" --texture "$work/trunc.png" --out "$work/r.png"
[ ! -e "$work/r.png" ] || { echo "FAIL truncated-texture: output written"; failures=$((failures + 1)); }

echo "$passed passed, $failures failed"
[ "$failures" -eq 0 ]
