#!/usr/bin/env bash
# The README's quality tables, produced from the binary (issue 14, Deliver 8):
# for every mesh in meshes/ (and any extra meshes given as arguments), the
# worst / average minimum dihedral angle and tet count of the input, after one
# and two default `tetrefine refine` steps (two steps only below 30k input
# tets, as in tests), and after `tetrefine improve`, each with
# `--effort fast` (the boundary fixed, the behaviour before boundary-aware
# improvement) and `--effort default`. Prints Markdown.
#
# Usage: benches/quality_tables.sh [EXTRA.mesh ...]
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
(cd "$ROOT" && cargo build --release --quiet --bin tetrefine)
T=${CARGO_TARGET_DIR:-$ROOT/target}/release/tetrefine
WORK=$(mktemp -d -t tetrefine-tables.XXXXXX)
PY=${PYTHON:-python3}
meshes=("$ROOT"/meshes/*.mesh "$@")

echo "| mesh | effort | input tets | input worst / avg | step 1 tets | step 1 worst / avg | step 2 tets | step 2 worst / avg | improve worst / avg | step 1 s |"
echo "|---|---|---:|---|---:|---|---:|---|---|---:|"
for m in "${meshes[@]}"; do
    name=$(basename "$m" .mesh)
    n=$("$T" quality "$m" --json | "$PY" -c 'import json,sys; print(json.load(sys.stdin)["tets"])')
    steps=1
    [ "$n" -lt 30000 ] && steps=2
    for effort in fast default; do
        "$T" refine "$m" -o "$WORK/out.mesh" --steps "$steps" --effort "$effort" \
            --stats "$WORK/s.json" >/dev/null 2>&1
        "$T" improve "$m" -o "$WORK/imp.mesh" --effort "$effort" >/dev/null 2>&1
        "$T" quality "$WORK/imp.mesh" --json >"$WORK/imp.json"
        "$PY" - "$WORK/s.json" "$WORK/imp.json" "$name" "$effort" <<'PYEOF'
import json, sys
steps = json.load(open(sys.argv[1]))["steps"]
imp = json.load(open(sys.argv[2]))
cell = lambda s: f"{s['min_dihedral_deg']['worst']:.2f}° / {s['min_dihedral_deg']['avg']:.2f}°"
row = [sys.argv[3], sys.argv[4], f"{steps[0]['tets']:,}", cell(steps[0])]
for k in (1, 2):
    row += [f"{steps[k]['tets']:,}", cell(steps[k])] if k < len(steps) else ["", ""]
row += [cell(imp), f"{steps[1]['seconds']:.2f}"]
print("| " + " | ".join(row) + " |")
PYEOF
    done
done
rm -rf "$WORK"
