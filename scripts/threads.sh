#!/usr/bin/env bash
# The table of docs/performance.md "Two threads": one thread against two on the fast engine, for
# the 20k, 100k and 1M blocks (cube at resolution 15, 26 and 55: 20,250, 105,456 and 998,250
# tets; edges + volume) at 10 and at 100 substeps, by `tetlab bench` (ms a frame, the median of
# ROUNDS runs of each, one thread and two in turn; 3 rounds by default).
# Usage: scripts/threads.sh [ROUNDS] > /tmp/table.md
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-3}
cargo build --release --quiet
tetlab=${CARGO_TARGET_DIR:-target}/release/tetlab

echo "| block | substeps | one thread, ms a frame | two threads | speed-up |"
echo "| --- | --- | --- | --- | --- |"
for case in "20k 15" "100k 26" "1M 55"; do
  set -- $case
  for substeps in 10 100; do
    # Fewer frames where a frame is long.
    frames=$(( 2000000 / ($2 * $2 * $2 * substeps) + 2 ))
    for _ in $(seq "$rounds"); do
      for threads in 1 2; do
        echo "$threads $("$tetlab" bench --scene cube --resolution "$2" --substeps "$substeps" \
          --frames "$frames" --warmup 1 --threads "$threads" --json | tail -n 1)"
      done
    done | python3 -c '
import json, statistics, sys
block, substeps = sys.argv[1], sys.argv[2]
runs = {"1": [], "2": []}
for line in sys.stdin:
    threads, text = line.split(" ", 1)
    runs[threads].append(json.loads(text)["ms_per_frame"])
one, two = statistics.median(runs["1"]), statistics.median(runs["2"])
print("| %s | %s | %.2f | %.2f | %.2fx |" % (block, substeps, one, two, one / two))
' "$1" "$substeps"
  done
done
