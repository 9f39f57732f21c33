#!/usr/bin/env bash
# Runs every experiment of docs/experiments.md and prints its tables in Markdown.
# Each row is one `tetlab run` command, shown in the row; the numbers are its last frame, on the
# reference engine (f64, one constraint at a time). The last column is the same command on the
# fast engine (`--engine fast`): a recovery that hangs on the order of the projections can differ
# there, since the fast engine projects in colours (scripts/orderings.sh counts k of N).
# Usage: scripts/experiments.sh > /tmp/tables.md   (needs the shared meshes in ../shared/meshes)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
tetlab=${CARGO_TARGET_DIR:-target}/release/tetlab
bunny=../shared/meshes/bunny.node

header() {
  echo
  echo "### $1"
  echo
  echo "| constraints | substeps × iterations | inverted at the end | last frame with an inverted tet | min V/V₀ | volume error | max edge strain | command | fast engine: inverted at the end, min V/V₀, max edge strain |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
}

# launched ARGS...: ARGS, with --no-settle-edits when they perturb the body. The tables measure
# what the constraints do with a perturbed body as the source note's demo has it, launched at
# v = Δx/h by the first substeps' corrections; settled, the command line's default since, is what
# the claims of the next section and the README run.
launched() {
  case " $* " in
    *" --perturb "*) echo "$* --no-settle-edits" ;;
    *) echo "$*" ;;
  esac
}

# fast_cell ARGS...: the last frame of `tetlab run ARGS --engine fast`, as one table cell.
fast_cell() {
  "$tetlab" run "$@" --engine fast --json | python3 -c '
import json, sys
last = [json.loads(line) for line in sys.stdin][-1]
print("{}, {:.3g}, {:.2e}".format(last["inverted_tets"], last["min_volume_ratio"] + 0.0, last["max_edge_strain"]))
'
}

# row ARGS...: runs `tetlab run ARGS --json` and prints one table row.
row() {
  set -- $(launched "$@")
  local args="$* --engine reference" line
  line=$("$tetlab" run $args --json | python3 -c '
import json, sys
args = sys.argv[1]
frames = [json.loads(line) for line in sys.stdin]
first, last = frames[0], frames[-1]
inverted = [f["frame"] for f in frames if f["inverted_tets"] > 0]
def option(name, default):
    words = args.split()
    return words[words.index(name) + 1] if name in words else default
constraints = option("--constraints", "edges,volume").replace(",", "+")
steps = option("--substeps", "100") + " × " + option("--iterations", "1")
print("| {} | {} | {} of {} | {} | {:.3g} | {:.2e} | {:.2e} | `tetlab run {}` |".format(
    constraints, steps, last["inverted_tets"], first["tets"],
    inverted[-1] if inverted else "none", last["min_volume_ratio"] + 0.0, last["volume_error"],
    last["max_edge_strain"], args))
' "$args")
  echo "$line $(fast_cell "$@") |"
}

families="edges height volume edges,volume edges,height height,volume edges,height,volume"

header "1. One tet, vertex 0 reflected through its opposite face (\`--perturb invert\`), 300 frames"
for c in $families; do row --scene tet --perturb invert --constraints $c --substeps 10; done

header "2. One tet, inverted, no gravity (\`--gravity 0\`)"
for c in $families; do row --scene tet --perturb invert --constraints $c --gravity 0 --substeps 10; done

header "3. Cube 4×4×4 (384 tets) mirrored: every tet inverted, every edge length kept"
for c in $families; do row --scene cube --perturb mirror --constraints $c --substeps 10; done

header "4. Cube 4×4×4 flattened onto the ground: every tet flat"
for c in $families; do row --scene cube --perturb flatten --constraints $c --substeps 10; done

header "5. Cube 4×4×4 at rest under gravity: does a family alone hold the shape?"
for c in edges height volume; do row --scene cube --constraints $c --substeps 10; done

header "6. Bunny flattened, rigid edges (compliance 0), gravity 10"
for s in 1 10; do for c in $families; do row --scene $bunny --perturb flatten --gravity 10 --constraints $c --substeps $s; done; done

header "7. Bunny mirrored, rigid edges, gravity 10"
for c in $families; do row --scene $bunny --perturb mirror --gravity 10 --constraints $c --substeps 10; done

header "8. The headline: bunny flattened with the teaching demo's soft edges (compliance 0.1 at density 1000, its 100 at density 1), gravity 10"
for s in 1 2 5 10; do for c in edges,volume edges,height,volume; do
  row --scene $bunny --perturb flatten --gravity 10 --compliance edges=0.1 --constraints $c --substeps $s
done; done

header "9. Bunny resting on the ground, soft edges as in the demo"
for c in edges,volume edges,height,volume; do row --scene $bunny --gravity 10 --compliance edges=0.1 --constraints $c --substeps 10; done

header "10. One substep: more iterations instead of substeps (bunny flattened, gravity 10)"
for ec in 0 0.1; do for i in 1 2 5 20; do
  row --scene $bunny --perturb flatten --gravity 10 --compliance edges=$ec --constraints edges,height,volume --substeps 1 --iterations $i
done; done

armadillo=../shared/meshes/armadillo_4k.node
materials="edges,volume edges,height,volume neohookean neohookean,height"

# inversion_row ARGS...: one row of table 11, with the inverted tets over time.
inversion_row() {
  set -- $(launched "$@")
  local args="$* --engine reference" line
  line=$("$tetlab" run $args --json | python3 -c '
import json, sys
args = sys.argv[1]
frames = [json.loads(line) for line in sys.stdin]
first, last = frames[0], frames[-1]
inverted = [f["frame"] for f in frames if f["inverted_tets"] > 0]
words = args.split()
constraints = words[words.index("--constraints") + 1].replace(",", "+")
marks = [m for m in (1, 3, 10, 30, 100, 300) if m < last["frame"]] + [last["frame"]]
curve = " / ".join(str(frames[m]["inverted_tets"]) for m in marks)
print("| {} | {} | {} | {} | {:.3g} | {:.2e} | `tetlab run {}` |".format(
    constraints, first["tets"], curve, inverted[-1] if inverted else "none",
    last["min_volume_ratio"] + 0.0, last["max_edge_strain"], args))
' "$args")
  echo "$line $(fast_cell "$@") |"
}

echo
echo "### 11. Inversion: the neo-Hookean family (E = 1 MPa, ν = 0.3, the default material) against the geometric ones, 30 substeps"
echo
echo "| constraints | tets | inverted at frames 1 / 3 / 10 / 30 / 100 / 300 (/ 600) | last frame with an inverted tet | min V/V₀ at the end | max edge strain at the end | command | fast engine: inverted at the end, min V/V₀, max edge strain |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
for c in $materials; do inversion_row --scene cube --perturb mirror --constraints $c --substeps 30; done
for c in $materials; do inversion_row --scene cube --perturb flatten --constraints $c --substeps 30; done
for c in $materials; do inversion_row --scene $bunny --perturb flatten --gravity 10 --constraints $c --substeps 30; done
for c in $materials; do inversion_row --scene $bunny --perturb mirror --gravity 10 --constraints $c --substeps 30; done
for c in $materials; do inversion_row --scene $armadillo --gravity 10 --constraints $c --substeps 30 --frames 600; done

header "12. How stiff a material the substeps allow: the cube at rest under gravity, neo-Hookean, 300 frames"
for e in 1e6 1e7 1e8 1e9; do for s in 10 30 100; do
  row --scene cube --constraints neohookean --material E=$e,nu=0.3 --substeps $s
done; done

header "13. Iterations and the stiffness a material shows: the cube damped to rest (damping 20), volume error = sag"
for m in xpbd pbd; do for i in 1 4 16; do for e in 2.5e6 1e7; do
  row --scene cube --constraints neohookean --material E=$e,nu=0.3 --damping 20 --solver $m --iterations $i --substeps 10
done; done; done

# beam_row ARGS...: a cantilever run, its tip deflection against Euler–Bernoulli.
beam_row() {
  set -- $(launched "$@")
  local args="$* --engine reference" line
  line=$("$tetlab" run $args --json | python3 -c '
import json, sys
args = sys.argv[1]
frames = [json.loads(line) for line in sys.stdin]
first, last = frames[0], frames[-1]
words = args.split()
def option(name, default):
    return words[words.index(name) + 1] if name in words else default
material = dict(kv.split("=") for kv in option("--material", "E=1e6,nu=0.3").split(","))
E, rho, g, L, h = float(material["E"]), 1000.0, 9.81, 2.0, 0.5
# Euler–Bernoulli: q = rho g A, I = h^4 / 12, delta = q L^4 / (8 E I) = 1.5 rho g L^4 / (E h^2)
theory = 1.5 * rho * g * L**4 / (E * h**2)
print("| {} | {} | {} | {} × {} | {:.4f} | {:.4f} | {:.3f} | `tetlab run {}` |".format(
    option("--resolution", "4"), first["tets"], option("--solver", "xpbd"),
    option("--substeps", "100"), option("--iterations", "1"),
    last["max_displacement"], theory, last["max_displacement"] / theory, args))
' "$args")
  local fast
  fast=$("$tetlab" run "$@" --engine fast --json | python3 -c '
import json, sys
print("{:.4f}".format([json.loads(line) for line in sys.stdin][-1]["max_displacement"]))
')
  echo "$line $fast |"
}

echo
echo "### 14. A cantilever under gravity against Euler–Bernoulli: the beam (2 m × 0.5 m × 0.5 m, clamped at x = 0), E = 10 MPa, ν = 0.3, damped to rest (damping 10, 5 s)"
echo
echo "| resolution | tets | solver | substeps × iterations | tip deflection (m) | Euler–Bernoulli (m) | ratio | command | fast engine: tip deflection (m) |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
beam="--scene beam --constraints neohookean --material E=1e7,nu=0.3 --damping 10 --frames 300"
for r in 1 2 4; do beam_row $beam --resolution $r --substeps 40 --iterations 4; done
for m in xpbd pbd; do for i in 1 4 16; do beam_row $beam --resolution 2 --substeps 20 --iterations $i --solver $m; done; done
for s in 10 20 40; do beam_row $beam --resolution 2 --substeps $s --iterations 4; done

# defaults_row ARGS...: a scene under the defaults (or the substeps given), 10 s.
defaults_row() {
  set -- $(launched "$@")
  local args="$* --engine reference" line
  line=$("$tetlab" run $args --frames 600 --json | python3 -c '
import json, sys
args = sys.argv[1]
frames = [json.loads(line) for line in sys.stdin]
first, last = frames[0], frames[-1]
inverted = [f["frame"] for f in frames if f["inverted_tets"] > 0]
words = args.split()
scene = words[words.index("--scene") + 1].split("/")[-1]
steps = words[words.index("--substeps") + 1] if "--substeps" in words else "100 (default)"
worst = max(frames, key=lambda f: f["max_edge_strain"])
print("| {} | {} | {} | {} | {} | {:.3f} (frame {}) | {:.4f} | `tetlab run {} --frames 600` |".format(
    scene, first["tets"], steps, last["inverted_tets"], inverted[-1] if inverted else "none",
    worst["max_edge_strain"], worst["frame"], last["max_edge_strain"], args))
' "$args")
  echo "$line $(fast_cell "$@" --frames 600) |"
}

echo
echo "### 15. Every scene under the defaults (edges + volume, rigid, gravity 9.81, 100 substeps), 10 s; then fewer substeps"
echo
echo "| scene | tets | substeps | inverted at the end | last frame with an inverted tet | largest edge strain during the run | edge strain at the end | command | fast engine: inverted at the end, min V/V₀, max edge strain |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
for s in tet cube beam ball $bunny $armadillo ../shared/meshes/ball_v41.msh ../shared/meshes/ball_v22.msh ../shared/meshes/beam_v41.msh; do
  defaults_row --scene $s
done
for s in 10 30 50 60 80; do defaults_row --scene $armadillo --substeps $s; done
for s in 10 30 50; do defaults_row --scene ../shared/meshes/ball_v41.msh --substeps $s; done

# The README's claims and the headline's as k of N projection orders on both engines.
TETLAB="$tetlab" scripts/orderings.sh

# The validation suite against theory, both engines, every case (13 min on 2 cores): the table of
# "Checked against theory", with a command per row; exit status 1 when a check fails.
echo
echo "### Checked against theory (tetlab validate --full)"
echo
"$tetlab" validate --full | python3 -c '
import sys
for line in sys.stdin:
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    if len(cells) != 12 or "frame speed" in cells[2]:
        continue
    case, engine, quantity, theory, source, exact, measured, solver, mesh, total, criterion, result = cells
    if case == "case":
        print("| case | engine | quantity | theory (source) | exact on the mesh | XPBD | solver'"'"'s error | mesh'"'"'s error | against theory | criterion | result | command |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    elif not case.startswith("---"):
        print(f"| {case} | {engine} | {quantity} | {theory} ({source}) | {exact} | {measured} | {solver} | {mesh} | {total} | {criterion} | {result} | `tetlab validate {case} --full --engine {engine}` |")
'
