#!/usr/bin/env bash
# Side-by-side refinement benchmark on one input mesh:
#
#   tetrefine √3   STEPS uniform √3 steps    tetrefine refine IN -o OUT.vtu --steps STEPS
#   TetGen         Debian's tetgen -r        -rqQa<vol>, <vol> set for a similar tet count
#   MMG3D -optim   mmg3d_O3 (PyPI mmgpy)     quality optimization at the input's sizes
#   MMG3D -hsiz    mmg3d_O3 (PyPI mmgpy)     uniform size <h>, set for a similar tet count, -hausd h/4
#   tetrefine 1:8  uniform red refinement    tetrefine bisect IN -o OUT.vtu
#
# Every tool runs under /usr/bin/time -v (wall seconds and peak resident
# memory of the whole process, reading and writing included) and every output
# is scored by `tetrefine quality --json`. Prints one Markdown table.
#
# Usage: benches/compare.sh IN [WORKDIR [STEPS]]
#   IN       any mesh tetrefine reads (.mesh, .msh, .vtu, .node)
#   WORKDIR  where inputs/outputs/logs go (default: a new temporary directory)
#   STEPS    √3 steps (default 1): the others are set for the count STEPS
#            steps give; the 1:8 bisection runs min(STEPS, 2) steps
#
# Runs on a fresh machine as root: installs `time` and `tetgen` with apt-get
# and `mmgpy` with pip when they are missing, and builds tetrefine in release.
set -euo pipefail

if [ $# -lt 1 ] || [ $# -gt 3 ]; then
    echo "usage: $0 IN [WORKDIR [STEPS]]" >&2
    exit 2
fi
STEPS=${3:-1}
case "$STEPS" in
    [1-9]) ;;
    *) echo "error: STEPS must be 1 to 9, not '$STEPS'" >&2; exit 2 ;;
esac
IN=$(realpath "$1")
[ -f "$IN" ] || { echo "error: $1: no such file" >&2; exit 1; }
ROOT=$(cd "$(dirname "$0")/.." && pwd)
WORK=${2:-$(mktemp -d -t tetrefine-compare.XXXXXX)}
mkdir -p "$WORK"
WORK=$(realpath "$WORK")
PY=${PYTHON:-python3}

say() { echo "compare: $*" >&2; }

# ---- tools ------------------------------------------------------------------
APT_UPDATED=0
apt_install() {
    if [ "$APT_UPDATED" = 0 ]; then
        say "apt-get update"
        apt-get update -qq >&2
        APT_UPDATED=1
    fi
    say "apt-get install -y $*"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >&2
}
[ -x /usr/bin/time ] || apt_install time
command -v tetgen >/dev/null || apt_install tetgen
command -v "$PY" >/dev/null || apt_install python3 python3-pip

mmg_binary() {
    # The wheel ships the native binary inside the package; the mmg3d_O3 on
    # PATH is a Python wrapper around it, so time the native one.
    "$PY" - <<'EOF' 2>/dev/null
import os, mmgpy
p = os.path.join(os.path.dirname(mmgpy.__file__), "bin", "mmg3d_O3")
assert os.access(p, os.X_OK)
print(p)
EOF
}
if ! MMG=$(mmg_binary); then
    say "pip install mmgpy"
    "$PY" -m pip install -q mmgpy >&2 ||
        "$PY" -m pip install -q --break-system-packages mmgpy >&2
    MMG=$(mmg_binary) || { echo "error: mmgpy installed but its mmg3d_O3 binary was not found" >&2; exit 1; }
fi

say "cargo build --release"
(cd "$ROOT" && cargo build --release --quiet --bin tetrefine)
T=${CARGO_TARGET_DIR:-$ROOT/target}/release/tetrefine
[ -x "$T" ] || { echo "error: $T was not built" >&2; exit 1; }

# ---- helpers ----------------------------------------------------------------
# other NAME CMD...: as `run`, but another tool's failure (TetGen 1.5 asserts
# on some inputs) leaves a $WORK/NAME.failed marker, a "failed" row in the
# table and the other tools running; returns 1.
other() {
    local name=$1
    shift
    say "$name: $*"
    echo "$*" >"$WORK/$name.cmd"
    rm -f "$WORK/$name.failed"
    if ! /usr/bin/time -v -o "$WORK/$name.time" "$@" >"$WORK/$name.log" 2>&1; then
        say "$name failed; see $WORK/$name.log"
        tail -2 "$WORK/$name.log" >&2
        touch "$WORK/$name.failed"
        return 1
    fi
}

# run NAME CMD...: time CMD, log in $WORK/NAME.{log,time}.
run() {
    local name=$1
    shift
    say "$name: $*"
    echo "$*" >"$WORK/$name.cmd"
    if ! /usr/bin/time -v -o "$WORK/$name.time" "$@" >"$WORK/$name.log" 2>&1; then
        echo "error: $name failed; see $WORK/$name.log" >&2
        tail -5 "$WORK/$name.log" >&2
        exit 1
    fi
}

# score NAME OUTPUT: quality JSON of OUTPUT into $WORK/NAME.quality.json.
score() {
    "$T" quality "$2" --json >"$WORK/$1.quality.json"
}

# json FILE EXPR: a value from a JSON file (EXPR indexes `d`).
json() {
    "$PY" -c 'import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))' "$1" "$2"
}

# ---- input ------------------------------------------------------------------
# Copies in the formats the other tools read (not timed). The .mesh copy also
# keeps MMG from picking up a stray .sol file beside the original.
"$T" convert "$IN" "$WORK/in.mesh"
"$T" convert "$IN" "$WORK/in.node"
"$T" quality "$WORK/in.mesh" --json >"$WORK/input.quality.json"
N_IN=$(json "$WORK/input.quality.json" "d['tets']")
VOL=$(json "$WORK/input.quality.json" "d['volume']")
say "input: $N_IN tets, volume $VOL"

# ---- tetrefine √3 (sets the target count for the others) ---------------------
run sqrt3 "$T" refine "$IN" -o "$WORK/sqrt3.vtu" --steps "$STEPS" --stats "$WORK/sqrt3.stats.json"
score sqrt3 "$WORK/sqrt3.vtu"
TARGET=$(json "$WORK/sqrt3.quality.json" "d['tets']")
say "target tet count: $TARGET"

# within10 COUNT: whether COUNT is within 10 % of TARGET.
within10() {
    "$PY" -c 'import sys; c,t=map(float,sys.argv[1:]); sys.exit(0 if abs(c-t)<=0.1*t else 1)' "$1" "$TARGET"
}

# ---- TetGen -r with a volume bound -------------------------------------------
# TetGen's tets end up about half the bound on average (measured on
# mmg_tinyBoxt and on cube grids), so start at 2·V/target and rescale once.
A=$("$PY" -c "import sys; print('%.6g' % (2*$VOL/$TARGET))")
for attempt in 1 2 3; do
    rm -f "$WORK"/in.1.*
    other tetgen tetgen "-rqQa$A" "$WORK/in.node" || break
    score tetgen "$WORK/in.1.node"
    COUNT=$(json "$WORK/tetgen.quality.json" "d['tets']")
    within10 "$COUNT" && break
    A=$("$PY" -c "print('%.6g' % ($A*$COUNT/$TARGET))")
done

# ---- MMG3D -optim (quality optimization at the input's own sizes) -----------
# (at the input's sizes, so the same for any STEPS: run with STEPS = 1 only)
if [ "$STEPS" = 1 ]; then
    other mmg_optim "$MMG" -v 0 -optim "$WORK/in.mesh" -out "$WORK/mmg_optim.mesh" &&
        score mmg_optim "$WORK/mmg_optim.mesh"
fi

# ---- MMG3D -hsiz (uniform size for a similar count) --------------------------
# MMG's tets at size h average about 0.094 h³ (measured on mmg_tinyBoxt).
# MMG's default Hausdorff bound (0.01) binds before the size on curved
# inputs (the tripod at -hsiz 7.09 gave 101k tets, not 29k), so it is set
# to h/4, the same fraction of the size everywhere (tripod: -hsiz 1.9
# -hausd 0.5 gives 28.6k tets).
H=$("$PY" -c "print('%.6g' % (($VOL/(0.094*$TARGET))**(1/3)))")
for attempt in 1 2 3; do
    HAUSD=$("$PY" -c "print('%.6g' % ($H/4))")
    other mmg_hsiz "$MMG" -v 0 -hsiz "$H" -hausd "$HAUSD" "$WORK/in.mesh" -out "$WORK/mmg_hsiz.mesh" ||
        break
    score mmg_hsiz "$WORK/mmg_hsiz.mesh"
    COUNT=$(json "$WORK/mmg_hsiz.quality.json" "d['tets']")
    within10 "$COUNT" && break
    H=$("$PY" -c "print('%.6g' % ($H*($COUNT/$TARGET)**(1/3)))")
done

# ---- tetrefine 1:8 bisection --------------------------------------------------
run bisect "$T" bisect "$IN" -o "$WORK/bisect.vtu" --steps "$(( STEPS < 2 ? STEPS : 2 ))"
score bisect "$WORK/bisect.vtu"

# ---- table --------------------------------------------------------------------
"$PY" - "$WORK" "$IN" "$N_IN" "$T" "$MMG" "$STEPS" <<'EOF'
import json, os, re, sys

work, path, n_in, tetrefine, mmg, steps = sys.argv[1:7]
n_in, steps = int(n_in), int(steps)
rows = [
    (f"tetrefine √3 ({steps} step{'s' if steps > 1 else ''})", "sqrt3"),
    ("TetGen 1.5 `-rq -a`", "tetgen"),
    ("MMG3D 5.8 `-optim`", "mmg_optim"),
    ("MMG3D 5.8 `-hsiz`", "mmg_hsiz"),
    ("tetrefine 1:8 bisection", "bisect"),
]

def wall_seconds(text):
    m = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", text)
    parts = [float(x) for x in m.group(1).split(":")]
    s = 0.0
    for p in parts:
        s = 60 * s + p
    return s

def peak_mb(text):
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", text)
    return int(m.group(1)) / 1024

print(f"Input: `{os.path.basename(path)}`, {n_in:,} tets.\n")
print("| tool | seconds | output tets | output tets/s | min dihedral worst / avg (°) | max dihedral worst (°) | peak memory (MB) |")
print("|---|---:|---:|---:|---:|---:|---:|")
for label, name in rows:
    if not os.path.exists(os.path.join(work, name + ".cmd")):
        print(f"| {label} | not run (STEPS > 1) | | | | | |")
        continue
    if os.path.exists(os.path.join(work, name + ".failed")):
        print(f"| {label} | failed (see `{name}.log`) | | | | | |")
        continue
    t = open(os.path.join(work, name + ".time")).read()
    q = json.load(open(os.path.join(work, name + ".quality.json")))
    s, mb = wall_seconds(t), peak_mb(t)
    n = q["tets"]
    rate = n / s if s > 0 else float("inf")
    mn, mx = q["min_dihedral_deg"], q["max_dihedral_deg"]
    print(f"| {label} | {s:.2f} | {n:,} | {rate/1e6:.3g} M | {mn['worst']:.2f} / {mn['avg']:.2f} | {mx['worst']:.2f} | {mb:.0f} |")
print()
print("Commands (as run):")
print()
for label, name in rows:
    if not os.path.exists(os.path.join(work, name + ".cmd")):
        continue
    cmd = open(os.path.join(work, name + ".cmd")).read().strip()
    cmd = cmd.replace(work + "/", "").replace(tetrefine, "tetrefine").replace(mmg, "mmg3d_O3")
    cmd = cmd.replace(path, os.path.basename(path))
    print(f"- {label}: `{cmd}`")

# tetrefine's own timing of the refinement alone (the table's seconds are
# whole processes: reading, refining, writing).
sqrt3 = json.load(open(os.path.join(work, "sqrt3.stats.json")))
done = sqrt3["steps"][1:] if isinstance(sqrt3, dict) and "steps" in sqrt3 else []
inner = []
if done and all("seconds" in x for x in done):
    inner.append("√3 step" + ("s " if len(done) > 1 else " ")
                 + " + ".join(f"{x['seconds']:.2f}" for x in done) + " s")
m = re.search(r"step 1: .* ([0-9.]+) s \(", open(os.path.join(work, "bisect.log")).read())
if m:
    inner.append(f"bisection step {float(m.group(1)):.2f} s")
if inner:
    print()
    print("In-core refinement time reported by tetrefine itself: " + ", ".join(inner) + ".")
EOF
say "outputs and logs in $WORK"
