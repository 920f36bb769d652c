#!/usr/bin/env bash
# The README's figures on the boundary and interface rules (issue 20, point
# 3), produced from the binary. For every mesh in meshes/: the worst /
# average minimum dihedral angle and the change of the domain's volume after
# default `tetrefine refine` steps (two below 30k input tets, else one) under
# each `--boundary` rule; then, for the meshes with several regions, the
# same under each `--interfaces` rule with the largest change of one
# region's volume, and for gmsh_t16 the mean distance of its five spherical
# inclusions' interface points to the true spheres (centres and radius from
# meshes/t16.geo). Prints Markdown.
#
# Usage: benches/boundary_rules.sh
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
(cd "$ROOT" && cargo build --release --quiet --bin tetrefine)
T=${CARGO_TARGET_DIR:-$ROOT/target}/release/tetrefine
WORK=$(mktemp -d -t tetrefine-rules.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
PY=${PYTHON:-python3}

# Region volumes of a Medit mesh and, for gmsh_t16, the inclusions' mean
# distance to their spheres: "volumes as JSON" and "distance or -".
measure() {
    "$PY" - "$1" "$2" <<'PYEOF'
import json, sys
from collections import defaultdict
tok = open(sys.argv[1]).read().split()
i = tok.index("Vertices"); n = int(tok[i + 1])
pts = [tuple(map(float, tok[i + 2 + 4 * k:i + 5 + 4 * k])) for k in range(n)]
j = tok.index("Tetrahedra"); m = int(tok[j + 1])
tets = [tuple(int(x) for x in tok[j + 2 + 5 * k:j + 7 + 5 * k]) for k in range(m)]
vol = defaultdict(float)
def sub(a, b): return (a[0] - b[0], a[1] - b[1], a[2] - b[2])
faces = {}
iface = defaultdict(set)
for t in tets:
    a, b, c, d = (pts[v - 1] for v in t[:4])
    u, v, w = sub(b, a), sub(c, a), sub(d, a)
    det = (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
           + u[2] * (v[0] * w[1] - v[1] * w[0]))
    vol[t[4]] += abs(det) / 6
    if sys.argv[2] == "spheres":
        for f in ((1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2)):
            key = tuple(sorted(t[q] for q in f))
            r = faces.pop(key, None)
            if r is None:
                faces[key] = t[4]
            elif r != t[4]:
                for k in (r, t[4]):
                    if 1 <= k <= 5:
                        iface[k].update(key)
dist = "-"
if sys.argv[2] == "spheres":
    ds = []
    for k, vs in iface.items():
        c = (0.166 * k, 0.75, 0.166 * k)
        ds += [abs(sum((pts[v - 1][q] - c[q]) ** 2 for q in range(3)) ** 0.5 - 0.09) for v in vs]
    dist = f"{sum(ds) / len(ds):.2e}"
print(json.dumps({str(k): v for k, v in vol.items()}))
print(dist)
PYEOF
}

steps_for() {
    local n
    n=$("$T" quality "$1" --json | "$PY" -c 'import json,sys; print(json.load(sys.stdin)["tets"])')
    if [ "$n" -lt 30000 ]; then echo 2; else echo 1; fi
}

echo "| mesh | steps | --boundary | tets | worst / avg | domain volume change |"
echo "|---|---:|---|---:|---|---:|"
for m in "$ROOT"/meshes/*.mesh; do
    name=$(basename "$m" .mesh)
    steps=$(steps_for "$m")
    for rule in interpolating approximating linear; do
        "$T" refine "$m" -o "$WORK/o.mesh" --steps "$steps" --boundary "$rule" \
            --stats "$WORK/s.json" >/dev/null 2>&1
        "$PY" - "$WORK/s.json" "$name" "$steps" "$rule" <<'PYEOF'
import json, sys
s = json.load(open(sys.argv[1]))["steps"]
a, b = s[0], s[-1]
d = b["min_dihedral_deg"]
change = 100 * (b["volume"] - a["volume"]) / a["volume"]
print(f"| {sys.argv[2]} | {sys.argv[3]} | {sys.argv[4]} | {b['tets']:,} | "
      f"{d['worst']:.2f}° / {d['avg']:.2f}° | {change:+.3f} % |")
PYEOF
    done
done

echo
echo "| mesh | steps | --interfaces | --boundary | tets | worst / avg | largest region volume change | inclusions' mean distance to their spheres |"
echo "|---|---:|---|---|---:|---|---:|---:|"
for name in gmsh_t16 mmg_tinyBoxt tetgen_example; do
    m="$ROOT/meshes/$name.mesh"
    steps=$(steps_for "$m")
    kind=none
    [ "$name" = gmsh_t16 ] && kind=spheres
    measure "$m" "$kind" >"$WORK/in.txt"
    for rules in "linear interpolating" "sqrt3 interpolating" "sqrt3 approximating"; do
        read -r rule boundary <<<"$rules"
        "$T" refine "$m" -o "$WORK/o.mesh" --steps "$steps" --interfaces "$rule" \
            --boundary "$boundary" --stats "$WORK/s.json" >/dev/null 2>&1
        measure "$WORK/o.mesh" "$kind" >"$WORK/out.txt"
        "$PY" - "$WORK/s.json" "$WORK/in.txt" "$WORK/out.txt" "$name" "$steps" "$rule" "$boundary" <<'PYEOF'
import json, sys
s = json.load(open(sys.argv[1]))["steps"][-1]
v0 = json.loads(open(sys.argv[2]).readline())
lines = open(sys.argv[3]).read().split("\n")
v1, dist = json.loads(lines[0]), lines[1]
worst = max(abs(v1[k] - v0[k]) / v0[k] for k in v0)
d = s["min_dihedral_deg"]
print(f"| {sys.argv[4]} | {sys.argv[5]} | {sys.argv[6]} | {sys.argv[7]} | {s['tets']:,} | "
      f"{d['worst']:.2f}° / {d['avg']:.2f}° | {100 * worst:.3f} % | {dist} |")
PYEOF
    done
done
