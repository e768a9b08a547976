#!/bin/sh
# test_viewer.sh - the viewer (examples/viewer/, issue 17) headless under Xvfb: each
# built-in scene and model renders a few frames at 320x240 into a PNG, and
# tests/png_check.c checks the file (structure, CRC-32, Adler-32, size, not blank) and
# where the body is: the cantilever's tip lower after its sag than at rest for every model
# and precision, the lobe's bottom lower after it hangs, the tip higher when the mouse drags
# it up (with a hand force in the readout), the free half gone when a scalpel stroke cuts
# the beam through, live key switches. Also a user's TetGen mesh, the same as a Gmsh file,
# a closed OBJ surface (frames' meshless sampling), and a bad argument. Prints PASS/FAIL
# per case and `RESULT <passed> <failed>` (tests/summarize.sh). Without the viewer binary (no
# GLFW), without xvfb-run or without Mesa's software renderer, prints one line and
# `RESULT 0 0`.
#
#   sh tests/test_viewer.sh VIEWER_BINARY TMP_DIR [name-filter]
#
# Run by the Makefile as build/viewer/test_viewer.result; about 3 s.
viewer=$1
tmp=$2
filter=$3
if [ ! -x "$viewer" ]; then
    echo "(no viewer binary at $viewer: GLFW missing, see 'make viewer'; the viewer tests are skipped)"
    echo "RESULT 0 0"
    exit 0
fi
if [ -z "$VW_UNDER_XVFB" ]; then
    if ! command -v xvfb-run >/dev/null 2>&1; then
        echo "(xvfb-run not found: the viewer tests are skipped; on Debian: apt-get install xvfb libgl1-mesa-dri)"
        echo "RESULT 0 0"
        exit 0
    fi
    swrast=""
    for f in /usr/lib/*/dri/swrast_dri.so /usr/lib/dri/swrast_dri.so /usr/lib64/dri/swrast_dri.so; do
        [ -e "$f" ] && swrast=$f
    done
    if [ -z "$swrast" ]; then
        echo "(Mesa's software renderer not found: the viewer tests are skipped; on Debian: apt-get install libgl1-mesa-dri)"
        echo "RESULT 0 0"
        exit 0
    fi
    # one virtual X server for every case; Mesa's software renderer
    VW_UNDER_XVFB=1 LIBGL_ALWAYS_SOFTWARE=1 exec xvfb-run -a -s "-screen 0 640x480x24" sh "$0" "$@"
fi
passed=0
failed=0
rm -rf "$tmp"
mkdir -p "$tmp" || exit 1
cc -std=c99 -O1 -o "$tmp/png_check" tests/png_check.c || { echo "RESULT 0 1 png_check did not build"; exit 1; }

report() {
    if [ "$2" -eq 0 ]; then
        passed=$((passed + 1)); echo "PASS $1"
    else
        failed=$((failed + 1)); echo "FAIL $1: $3"
    fi
}
want() { case "$1" in *"$filter"*) return 0 ;; esac; return 1; }

# shot NAME ARGS...: renders into $tmp/NAME.png at 320x240; sets $w $h $count $x0 $x1 $y0
# $y1 $top $bottom from png_check; returns non-zero (with $why) if the viewer or the check
# failed, the size is wrong or the picture is blank.
shot() {
    name=$1; shift
    why=""
    if ! "$viewer" --size 320x240 --screenshot "$tmp/$name.png" "$@" > "$tmp/$name.out" 2>&1; then
        why="viewer failed: $(tail -n 2 "$tmp/$name.out" | tr '\n' ' ')"; return 1
    fi
    if ! set -- $("$tmp/png_check" "$tmp/$name.png" 2>&1); then why="png_check failed"; return 1; fi
    if [ $# -ne 9 ]; then why="png_check: $*"; return 1; fi
    w=$1 h=$2 count=$3 x0=$4 x1=$5 y0=$6 y1=$7 top=$8 bottom=$9
    if [ "$w" -ne 320 ] || [ "$h" -ne 240 ]; then why="size ${w}x$h, expected 320x240"; return 1; fi
    if [ "$count" -lt 2000 ]; then why="nearly blank: $count body pixels"; return 1; fi
    return 0
}

# the cantilever at rest: the reference for the sag, pull and cut cases
rest_bottom=""
if shot rest --frames 0; then
    report cantilever_rest_picture 0 ""
    rest_bottom=$bottom rest_top=$top rest_x0=$x0 rest_x1=$x1
else report cantilever_rest_picture 1 "$why"; fi

# sag NAME ARGS...: the tip's lowest pixel at least 4 rows below its place at rest after 11
# frames (0.18 s, about half the first bending period: the sag's deepest point)
sag() {
    name=$1; shift
    want "$name" || return 0
    if [ -z "$rest_bottom" ]; then report "$name" 1 "no rest picture"; return 0; fi
    if ! shot "$name" --frames 11 "$@"; then report "$name" 1 "$why"; return 0; fi
    if [ "$bottom" -ge $((rest_bottom + 4)) ]; then report "$name" 0 ""
    else report "$name" 1 "tip bottom row $bottom, at rest $rest_bottom: no sag"; fi
}
sag cantilever_tensormass_sag --model tensormass
sag cantilever_tensormass_float_explicit_sag --model tensormass --precision float --integrator explicit --field J
sag cantilever_heml_sag --model heml --field stress
sag cantilever_heml_float_sag --model heml --precision float --integrator linearized
sag cantilever_frames_sag --model frames

# live switches through the keys: M twice (heml, then frames), P (float); frames still sags
sag cantilever_keys_frames_float_sag --keys mmp
if want keys_readout; then
    if grep -q 'frames SVK float' "$tmp/cantilever_keys_frames_float_sag.out"; then report keys_readout 0 ""
    else report keys_readout 1 "$(grep '^readout' "$tmp/cantilever_keys_frames_float_sag.out")"; fi
fi

# a hand: press on the tip (its middle row, 2 pixels in from its end) and move the mouse
# 40 pixels up: the tip rises, and the readout shows the force it pulls back with
if want cantilever_drag_up; then
    gx=$((rest_x1 - 2)) gy=$(((rest_top + rest_bottom) / 2))
    if shot drag --frames 20 --drag "$gx,$gy,0,-40" && [ "$top" -le $((rest_top - 15)) ] &&
       grep -q 'hand force [1-9]' "$tmp/drag.out"; then report cantilever_drag_up 0 ""
    else report cantilever_drag_up 1 "${why:-tip top row $top, at rest $rest_top; $(grep -o 'hand force [^|]*' "$tmp/drag.out")}"; fi
fi

# a scalpel stroke down across the middle of the beam: the free half falls out of the
# picture (0.5 m in 20 frames) and the tip's z drops below -0.2 m
if want cantilever_scalpel; then
    sx=$(((rest_x0 + rest_x1) / 2)) half=$((rest_x0 + (rest_x1 - rest_x0) * 6 / 10))
    if shot cut --frames 20 --stroke "$sx,$((rest_top - 20)),$sx,$((rest_bottom + 20))" &&
       grep -q '^cut: [1-9]' "$tmp/cut.out" && [ "$x1" -le "$half" ] &&
       grep -q '^tip: [^ ]* [^ ]* -0*\.[2-9]' "$tmp/cut.out"; then report cantilever_scalpel 0 ""
    else report cantilever_scalpel 1 "${why:-rightmost body column $x1, at rest $rest_x1; $(grep -h '^cut\|^tip' "$tmp/cut.out" | tr '\n' ' ')}"; fi
fi

if want lobe_hangs; then
    if shot lobe_rest --scene lobe --frames 0 && lobe_bottom=$y1 &&
       shot lobe --scene lobe --frames 20 && [ "$y1" -ge $((lobe_bottom + 3)) ]; then report lobe_hangs 0 ""
    else report lobe_hangs 1 "${why:-bottom row $y1, at rest $lobe_bottom}"; fi
fi

# a user's TetGen mesh: one cube of 5 tetrahedra
if want tetgen_mesh; then
    printf '8 3 0 0\n0 0 0 0\n1 .1 0 0\n2 0 .1 0\n3 .1 .1 0\n4 0 0 .1\n5 .1 0 .1\n6 0 .1 .1\n7 .1 .1 .1\n' > "$tmp/cube.node"
    printf '5 4 0\n0 0 1 3 5\n1 0 3 2 6\n2 0 5 4 6\n3 3 6 5 7\n4 0 3 6 5\n' > "$tmp/cube.ele"
    if shot tetgen --mesh "$tmp/cube.node" --frames 5; then report tetgen_mesh 0 ""
    else report tetgen_mesh 1 "$why"; fi
fi

# the same cube as a Gmsh 2.2 file
if want gmsh_mesh; then
    { printf '$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n'
      printf '1 0 0 0\n2 .1 0 0\n3 0 .1 0\n4 .1 .1 0\n5 0 0 .1\n6 .1 0 .1\n7 0 .1 .1\n8 .1 .1 .1\n$EndNodes\n'
      printf '$Elements\n5\n1 4 2 0 1 1 2 4 6\n2 4 2 0 1 1 4 3 7\n3 4 2 0 1 1 6 5 7\n'
      printf '4 4 2 0 1 4 7 6 8\n5 4 2 0 1 1 4 7 6\n$EndElements\n'; } > "$tmp/cube.msh"
    if shot gmsh --mesh "$tmp/cube.msh" --model heml --frames 5; then report gmsh_mesh 0 ""
    else report gmsh_mesh 1 "$why"; fi
fi

# a closed OBJ surface: a box, simulated by frames sampled inside it
if want obj_surface; then
    printf 'v 0 0 0\nv .2 0 0\nv 0 .1 0\nv .2 .1 0\nv 0 0 .1\nv .2 0 .1\nv 0 .1 .1\nv .2 .1 .1\n' > "$tmp/box.obj"
    printf 'f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n' >> "$tmp/box.obj"
    if shot obj --mesh "$tmp/box.obj" --frames 5 && grep -q 'frames SVK' "$tmp/obj.out"; then report obj_surface 0 ""
    else report obj_surface 1 "${why:-not simulated by frames: $(head -n 1 "$tmp/obj.out")}"; fi
fi

if want bad_argument; then
    "$viewer" --bogus > /dev/null 2> "$tmp/bad.err"
    st=$?
    if [ "$st" -eq 2 ] && grep -q '^usage' "$tmp/bad.err"; then report bad_argument 0 ""
    else report bad_argument 1 "exit status $st"; fi
fi

echo "RESULT $passed $failed"
[ "$failed" -eq 0 ]
