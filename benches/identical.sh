#!/usr/bin/env bash
# Byte-identical outputs of two tetrefine binaries (before / after a change
# that must not change results), compared with `cmp`:
#
#   benches/identical.sh BASE_BIN NEW_BIN [WORKDIR]
#
# On every tet mesh of meshes/: `quality --json` (every file and format),
# `refine` (1 and 2 steps, each --boundary rule), `bisect` and `improve`
# (on the .mesh of every model), each written as .vtu (all cell arrays);
# and every `surface` scheme on small inputs written below. Timings are not
# compared (refine's printed table and --stats carry wall times). Prints one
# line per differing output and a summary; exits non-zero on any difference.
set -uo pipefail
base="$(realpath "$1")"
new="$(realpath "$2")"
cd "$(dirname "$0")/.."
work="${3:-$(mktemp -d)}"
mkdir -p "$work/base" "$work/new" "$work/in"
runs=0
diffs=0

# run NAME OUTFILE ARGS… : runs both binaries; compares OUTFILE (a path under
# the per-binary directory, or "-" for stdout) and the exit status.
run() {
  local name="$1" out="$2"
  shift 2
  local b
  for b in base new; do
    local bin
    [ "$b" = base ] && bin="$base" || bin="$new"
    local args=()
    local a
    for a in "$@"; do args+=("${a//@OUT@/$work/$b}"); done
    "$bin" "${args[@]}" >"$work/$b/$name.stdout" 2>"$work/$b/$name.stderr"
    echo "$?" >"$work/$b/$name.rc"
  done
  runs=$((runs + 1))
  local f
  for f in "$name.rc" $([ "$out" = - ] && echo "$name.stdout" || echo "$out"); do
    if ! cmp -s "$work/base/$f" "$work/new/$f"; then
      echo "DIFFERENT: $name ($f)"
      diffs=$((diffs + 1))
    fi
  done
}

for m in meshes/*.mesh meshes/*.msh meshes/*.vtu; do
  n="$(basename "$m")"
  run "quality_$n" - quality "$m" --json
done

for m in meshes/*.mesh; do
  n="$(basename "$m" .mesh)"
  for rule in interpolating approximating linear; do
    for steps in 1 2; do
      run "refine_${n}_${rule}_$steps" "refine_${n}_${rule}_$steps.vtu" \
        refine "$m" -o "@OUT@/refine_${n}_${rule}_$steps.vtu" --steps "$steps" --boundary "$rule"
    done
  done
  run "bisect_$n" "bisect_$n.vtu" bisect "$m" -o "@OUT@/bisect_$n.vtu"
  run "improve_$n" "improve_$n.vtu" improve "$m" -o "@OUT@/improve_$n.vtu"
done

# Small surfaces: an octahedron (triangles), a cube (quads), a tetrahedron, an
# open triangle strip (boundary curves), and control points for the IFS.
cat >"$work/in/octa.obj" <<'OBJ'
v 1 0 0
v -1 0 0
v 0 1 0
v 0 -1 0
v 0 0 1
v 0 0 -1
f 1 3 5
f 3 2 5
f 2 4 5
f 4 1 5
f 3 1 6
f 2 3 6
f 4 2 6
f 1 4 6
OBJ
cat >"$work/in/cube.obj" <<'OBJ'
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
OBJ
cat >"$work/in/tet.off" <<'EOT'
OFF
4 4 6
0 0 0
1 0 0
0 1 0
0 0 1
3 0 2 1
3 0 1 3
3 0 3 2
3 1 2 3
EOT
cat >"$work/in/strip.ply" <<'PLY'
ply
format ascii 1.0
element vertex 6
property float x
property float y
property float z
element face 4
property list uchar int vertex_indices
end_header
0 0 0
1 0 0.2
2 0 0
0 1 0.1
1 1 0.3
2 1 0
3 0 1 4
3 0 4 3
3 1 2 5
3 1 5 4
PLY
cat >"$work/in/spline.obj" <<'OBJ'
v 0 0 0
v 1 2 0
v 2 -1 1
v 3 1 0
v 4 0 2
v 5 2 1
OBJ
cat >"$work/in/grid.obj" <<'OBJ'
v 0 0 0
v 1 0 1
v 2 0 0
v 3 0 1
v 0 1 1
v 1 1 0
v 2 1 1
v 3 1 0
v 0 2 0
v 1 2 1
v 2 2 0
v 3 2 1
v 0 3 1
v 1 3 0
v 2 3 1
v 3 3 0
OBJ
echo '{"iterations": [{"face_extrude": 0.2}, {"edge": 0.3, "vertex": -0.2}], "mu_by_valence": {"3": 0.5}}' >"$work/in/w.json"

i="$work/in"
s() { # s NAME EXT ARGS… : one surface run written to NAME.EXT
  local name="$1" ext="$2"
  shift 2
  run "surface_$name" "surface_$name.$ext" surface "$@" -o "@OUT@/surface_$name.$ext"
}
for scheme in sqrt3 sqrt3-interp sqrt3-linear loop; do
  s "${scheme}_octa" obj "$scheme" "$i/octa.obj" --steps 3
  s "${scheme}_strip" vtp "$scheme" "$i/strip.ply" --steps 2
  s "${scheme}_crease" ply "$scheme" "$i/octa.obj" --steps 2 --crease 0-2,2-1 --corner 4
done
s sqrt3_angle off sqrt3 "$i/tet.off" --steps 4 --crease-angle 40
s sqrt3_box vtk sqrt3 "$i/octa.obj" --steps 2 --select-box 0,-2,-2,2,2,2
s sqrt3_sphere obj sqrt3-interp "$i/octa.obj" --steps 2 --select-sphere 1,0,0,1.2
for scheme in catmull-clark doo-sabin; do
  s "${scheme}_cube" obj "$scheme" "$i/cube.obj" --steps 3
  s "${scheme}_tet" off "$scheme" "$i/tet.off" --steps 2
done
s catmull-clark_corner vtk catmull-clark "$i/cube.obj" --steps 2 --corner 0 --crease 0-1
s catmull-clark_strip obj catmull-clark "$i/strip.ply" --steps 2
s weighted obj catmull-clark-weighted "$i/cube.obj" --steps 3 --weights "$i/w.json"
s sierpinski obj sierpinski "$i/tet.off" --steps 3 --neck 0.02
s sierpinski_cube ply sierpinski "$i/cube.obj" --steps 2
s truncate off truncate "$i/cube.obj" --steps 3
s truncate_cut obj truncate "$i/tet.off" --steps 2 --cut 0.3
s ifs_koch vtp ifs --kind koch --iterations 6
s ifs_gasket csv ifs --kind gasket --iterations 5
s ifs_bspline csv ifs "$i/spline.obj" --kind cubic-bspline --iterations 8
s ifs_fourpoint vtp ifs "$i/spline.obj" --kind four-point --iterations 6
s ifs_bicubic vtp ifs "$i/grid.obj" --kind bicubic --grid 4,4 --iterations 4

echo "identical.sh: $runs runs, $diffs differing outputs (work dir $work)"
[ "$diffs" = 0 ]
