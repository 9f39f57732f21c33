#!/usr/bin/env bash
# The claims of the README and of docs/experiments.md's headline as k of N projection orders on
# both engines (`tetlab run --ensemble N`: order seeds 1..=N on the reference engine and on the
# fast one): 16 orderings for those claims, 4 for the other rows. Prints the table in Markdown,
# then its running time. docs/experiments.md ("Claims as k of N orderings") is its output. The
# README's claims run as the README writes them (edits settle, the default); the rows of the
# tables as the tables run them, launched (--no-settle-edits, scripts/experiments.sh).
# Usage: scripts/orderings.sh   (needs the shared meshes in ../shared/meshes)
set -euo pipefail
cd "$(dirname "$0")/.."
# TETLAB names a binary to use; without it, tetlab is built first.
[ -n "${TETLAB:-}" ] || cargo build --release --quiet
tetlab=${TETLAB:-${CARGO_TARGET_DIR:-target}/release/tetlab}
bunny=../shared/meshes/bunny.node
start=$(date +%s)

# claim N WHAT ARGS...: one row, `tetlab run ARGS --ensemble N --json`'s tally.
claim() {
  local n=$1 what=$2
  shift 2
  "$tetlab" run "$@" --ensemble "$n" --json | python3 -c '
import json, sys
what, args = sys.argv[1], sys.argv[2]
tally = [json.loads(l) for l in sys.stdin][-1]["ensemble"]
def cell(t):
    k, n = t["recovered"], t["members"]
    ends = sorted(set(t["inverted_at_the_end"]))
    text = "{} of {}".format(k, n)
    if k < n:
        text += " (the others end with {} inverted)".format(", ".join(str(e) for e in ends if e > 0) or "0")
    if t["thrown"]:
        text += ", {} thrown".format(t["thrown"])
    if t["diverged"]:
        text += ", {} diverged".format(t["diverged"])
    return text + "; strain at the end up to {:.2g}".format(t["largest_strain"])
print("| {} | {} | {} | `tetlab run {} --ensemble N` |".format(
    what, cell(tally["reference"]), cell(tally["fast"]), args))
' "$what" "$*"
}

echo
echo "### Claims as k of N orderings: recovers (no tet inverted at the end) in k of N projection orders"
echo
echo "| claim | reference engine | fast engine | command |"
echo "| --- | --- | --- | --- |"
claim 16 "README: the main job, the mirrored cube under edges + heights + volume" \
  --scene cube --perturb mirror --constraints edges,height,volume
claim 16 "README: the mirrored cube stays inverted under edges alone" \
  --scene cube --perturb mirror --constraints edges
claim 16 "README: the height file recovers the cube as the built-in heights do (the file)" \
  --scene cube --perturb mirror --constraints edges --constraint-file assets/constraints/height.toml
claim 16 "README: the same with the built-in heights" \
  --scene cube --perturb mirror --constraints edges,height
claim 16 "README: the flattened bunny, gravity 10, edges + heights + volume" \
  --scene $bunny --perturb flatten --gravity 10 --constraints edges,height,volume
claim 16 "headline: demo-like (soft edges + volume, 10 substeps) keeps tets inverted" \
  --scene $bunny --perturb flatten --gravity 10 --compliance edges=0.1 --constraints edges,volume --substeps 10 --frames 600 --no-settle-edits
claim 16 "headline: the same + heights recovers" \
  --scene $bunny --perturb flatten --gravity 10 --compliance edges=0.1 --constraints edges,height,volume --substeps 10 --frames 600 --no-settle-edits
claim 16 "headline: rigid edges + heights + volume, 10 substeps, recovers" \
  --scene $bunny --perturb flatten --gravity 10 --constraints edges,height,volume --substeps 10 --frames 600 --no-settle-edits
for c in edges,volume edges,height height,volume edges,height,volume; do
  claim 4 "table 3: the mirrored cube, ${c//,/ + }, 10 substeps" \
    --scene cube --perturb mirror --constraints $c --substeps 10 --no-settle-edits
done
claim 4 "table 4: the flattened cube, edges + height, 10 substeps" \
  --scene cube --perturb flatten --constraints edges,height --substeps 10 --no-settle-edits
claim 4 "table 5: the cube at rest under volume alone, 10 substeps" \
  --scene cube --constraints volume --substeps 10
for c in edges,volume edges,height height,volume edges,height,volume; do
  claim 4 "table 7: the mirrored bunny, rigid ${c//,/ + }, 10 substeps" \
    --scene $bunny --perturb mirror --gravity 10 --constraints $c --substeps 10 --no-settle-edits
done
for c in edges,volume edges,height,volume; do
  claim 4 "table 6: the flattened bunny, rigid ${c//,/ + }, 10 substeps" \
    --scene $bunny --perturb flatten --gravity 10 --constraints $c --substeps 10 --no-settle-edits
done
for s in ../shared/meshes/armadillo_4k.node ../shared/meshes/ball_v41.msh; do
  claim 4 "table 15: ${s##*/} under the defaults, 10 s" --scene $s --frames 600
done
echo
echo "scripts/orderings.sh took $(( $(date +%s) - start )) s on $(nproc) cores."
