#!/usr/bin/env bash
# The table of docs/performance.md "Against the 2x goal": each example constraint file against
# the built-in family it writes, on the fast engine, one thread, the 10^3-cell block of 6000 tets
# at the default 100 substeps. The built-in's and the file's commands run in turn, ROUNDS times
# (5 by default), and each row gives the median of the ns per projection "inside the sweeps".
# Usage: scripts/file-families.sh [ROUNDS] > /tmp/table.md
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-5}
cargo build --release --quiet
tetlab=${CARGO_TARGET_DIR:-target}/release/tetlab
common="bench --scene cube --resolution 10 --frames 60 --warmup 3 --threads 1 --json"

echo "| family | built-in, ns per projection | from a file, ns per projection | ratio | goal |"
echo "| --- | --- | --- | --- | --- |"
for family in volume height neohookean; do
  file=assets/constraints/$family.toml
  for _ in $(seq "$rounds"); do
    echo "builtin $("$tetlab" $common --constraints "$family" | tail -n 1)"
    echo "file $("$tetlab" $common --constraints none --constraint-file "$file" | tail -n 1)"
  done | python3 -c '
import json, statistics, sys
family, file = sys.argv[1], sys.argv[2]
runs = {"builtin": [], "file": []}
for line in sys.stdin:
    which, text = line.split(" ", 1)
    by_family = json.loads(text)["ns_per_projection_by_family"]
    # A pair (the neo-Hookean one) is timed as one sweep: each of its families shows the same.
    runs[which].append(max(by_family.values()))
b, f = statistics.median(runs["builtin"]), statistics.median(runs["file"])
ratio = f / b
print("| %s (`%s`) | %.2f | %.2f | %.2fx | <= 2x: %s |" % (
    family, file, b, f, ratio, "met" if ratio <= 2 else "missed"))
' "$family" "$file"
done
