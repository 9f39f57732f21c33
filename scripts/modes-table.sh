#!/usr/bin/env bash
# The table of docs/gradients.md "Along a flatten-and-invert path": for each family (and two
# example constraint files), the lowest eigenvalue of the energy Hessian of one tet and how many
# are negative, as its apex p3 = (0.25, 0.25, t) goes from rest (t = 1) through flat (t = 0) to
# inverted (t = -1) over the face p0 p1 p2, by `tetlab modes --json`. Each row ends with the
# options that name its energy; every cell is that command at its t (printed below the table).
# Usage: scripts/modes-table.sh > /tmp/table.md
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
tetlab=${CARGO_TARGET_DIR:-target}/release/tetlab
rest="0,0,0 1,0,0 0,1,0 0.25,0.25,1"
heights="1 0.5 0 -0.5 -1"

header="| family |"
rule="| --- |"
trailer=" options |"
for t in $heights; do
  header="$header t = $t |"
  rule="$rule --- |"
done
echo "$header$trailer"
echo "$rule --- |"
row() {
  local label=$1
  shift
  local line="| $label |"
  for t in $heights; do
    # shellcheck disable=SC2086
    cell=$("$tetlab" modes "$@" --rest-shape $rest --points 0,0,0 1,0,0 0,1,0 "0.25,0.25,$t" --json |
      python3 -c '
import json, sys
d = json.load(sys.stdin)
print("%.3g (%d negative, %d zero)" % (d["modes"][0]["eigenvalue"], d["negative_count"], d["zero_count"]))
')
    line="$line $cell |"
  done
  echo "$line \`$*\` |"
}
row "edges (α = 1)" --constraints edges
row "heights (α = 1)" --constraints height
row "volume (α = 1)" --constraints volume
row "neo-Hookean pair, E = 1 MPa, ν = 0.3" --constraints neohookean
row "\`assets/constraints/volume.toml\` (α = 1)" --constraints none --constraint-file assets/constraints/volume.toml
row "\`assets/constraints/neohookean.toml\`, E = 1 MPa, ν = 0.3" --constraints none --constraint-file assets/constraints/neohookean.toml
echo
echo "Each cell: \`tetlab modes OPTIONS --rest-shape $rest --points 0,0,0 1,0,0 0,1,0 0.25,0.25,T --json\`,"
echo "OPTIONS those of its row: the lowest eigenvalue, then the counts."
