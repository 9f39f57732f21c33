#!/usr/bin/env bash
# How often the reach rule (a projection's step longer than K
# longest rest edges of its element is skipped, `--reach K`, 100 by default) fires on the
# built-in families, and whether it changes an outcome. Every scene × perturbation × family set,
# settled (the default) and launched (--no-settle-edits), 120 frames, at reach 10, 30, 100 and
# 10⁹ (none in effect); a run "fires" when some projection was skipped as too long. Prints the
# table in Markdown.
# Usage: scripts/reach-battery.sh   (needs the shared meshes in ../shared/meshes)
#        REACHES="100" scripts/reach-battery.sh   (only the default reach against none: half the time)
set -euo pipefail
cd "$(dirname "$0")/.."
# TETLAB names a binary to use; without it, tetlab is built first.
[ -n "${TETLAB:-}" ] || cargo build --release --quiet
tetlab=${TETLAB:-${CARGO_TARGET_DIR:-target}/release/tetlab}
meshes=../shared/meshes
scenes="cube $meshes/bunny.node $meshes/armadillo_4k.node $meshes/ball_v41.msh"
perturbations="none mirror flatten scramble:1"
families="edges,volume edges,height height,volume edges,height,volume height volume"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# one RUN-NAME ARGS...: the summed too-long skips and the inverted tets at the end, one line.
jobs=()
for scene in $scenes; do for p in $perturbations; do for c in $families; do for settle in "" --no-settle-edits; do
  perturb=$([ "$p" = none ] && echo "" || echo "--perturb $p")
  jobs+=("--scene $scene $perturb --constraints $c $settle --frames 120")
done; done; done; done

reaches=${REACHES:-10 30 100}
for reach in $reaches 1e9; do
  printf '%s\n' "${jobs[@]}" | xargs -P "$(nproc)" -I{} sh -c '
    out=$("$0" run {} --reach "$1" --json 2>/dev/null | python3 -c "
import json, sys
frames = [json.loads(l) for l in sys.stdin]
skips = sum(v for f in frames for k, v in f.items() if k.startswith(\"skipped_too_long_\"))
print(skips, frames[-1][\"inverted_tets\"] if frames else \"diverged\")
" || echo "0 diverged")
    echo "{}|$out"' "$tetlab" "$reach" | sort >"$work/$reach"
done

total=${#jobs[@]}
echo
echo "### The reach rule: built-in families on every scene and perturbation ($total runs of 120 frames, settled and launched)"
echo
echo "| reach (longest rest edges) | runs where it skips a step | runs whose inverted count at the end differs from no rule (10⁹) | runs whose outcome (0 inverted at the end, or not) differs |"
echo "| --- | --- | --- | --- |"
for reach in $reaches; do
  fired=$(awk -F'|' '{split($2, a, " "); if (a[1] > 0) n++} END {print n + 0}' "$work/$reach")
  changed=$(paste -d'#' "$work/$reach" "$work/1e9" | awk -F'#' '{split($1, a, "|"); split($2, b, "|"); split(a[2], x, " "); split(b[2], y, " "); if (x[2] != y[2]) n++} END {print n + 0}')
  flipped=$(paste -d'#' "$work/$reach" "$work/1e9" | awk -F'#' '{split($1, a, "|"); split($2, b, "|"); split(a[2], x, " "); split(b[2], y, " "); if ((x[2] == 0) != (y[2] == 0)) n++} END {print n + 0}')
  echo "| $reach | $fired of $total | $changed of $total | $flipped of $total |"
done
echo
echo "Runs where the default reach (100) skips a step:"
echo
paste -d'#' "$work/100" "$work/1e9" | awk -F'#' '{split($1, a, "|"); split($2, b, "|"); split(a[2], x, " "); split(b[2], y, " "); if (x[1] > 0) print "- `tetlab run " a[1] "`: " x[1] " steps skipped, " x[2] " inverted at the end (" y[2] " with no rule)"}'
