#!/usr/bin/env bash
# tetlab's fast engine against Ten Minute Physics' own solver (10-softBodies.html, run in Node),
# on the same bunny (../shared/meshes/bunny, which is that page's mesh), edges + volume, 10
# substeps, one thread, gravity and ground: ROUNDS rounds of one run of each in turn, the median
# of each and of the ratios (docs/performance.md "Against Ten Minute Physics").
#
# The page is not in this repository. Download it once, e.g.
#   curl -o ~/.cache/tetlab/10-softBodies.html \
#     https://raw.githubusercontent.com/matthias-research/pages/2668faf9749fb87ad169eba287b6e6987ac98cc4/tenMinutePhysics/10-softBodies.html
# and give its path as PAGE (that is the default path).
# Usage: scripts/ten-minute-physics.sh [ROUNDS] [PAGE]
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-5}
page=${2:-$HOME/.cache/tetlab/10-softBodies.html}
mesh=../shared/meshes/bunny
if [ ! -f "$page" ]; then
  echo "error: $page: no Ten Minute Physics page there; the comment at the top of $0 says where to get it" >&2
  exit 2
fi
if [ ! -f "$mesh.node" ]; then
  echo "error: $mesh.node: the shared meshes are not beside this clone" >&2
  exit 2
fi
command -v node >/dev/null || { echo "error: node is not installed (apt-get install -y nodejs)" >&2; exit 2; }
cargo build --release --quiet
tetlab=${CARGO_TARGET_DIR:-target}/release/tetlab

for _ in $(seq "$rounds"); do
  echo "tmp $(node scripts/ten-minute-physics.mjs "$page" "$mesh" 2000 200)"
  echo "tetlab $("$tetlab" bench --scene "$mesh.node" --substeps 10 --threads 1 --frames 2000 \
    --warmup 200 --json | tail -n 1)"
done | python3 -c '
import json, statistics, sys
runs = {"tmp": [], "tetlab": []}
for line in sys.stdin:
    who, text = line.split(" ", 1)
    runs[who].append(json.loads(text)["ms_per_frame"])
ratios = [t / f for t, f in zip(runs["tmp"], runs["tetlab"])]
print("| solver | ms a frame (median of %d) |" % len(ratios))
print("| --- | --- |")
print("| Ten Minute Physics, Node %s | %.3f |" % (sys.argv[1], statistics.median(runs["tmp"])))
print("| tetlab fast engine, one thread | %.3f |" % statistics.median(runs["tetlab"]))
print("ratio per round: %s; median %.1fx" % (", ".join("%.1fx" % r for r in ratios), statistics.median(ratios)))
' "$(node --version)"
