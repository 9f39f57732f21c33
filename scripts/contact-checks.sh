#!/usr/bin/env bash
# The contact checks of docs/experiments.md ("Contact") as k of N projection orders on both
# engines: each check runs under order seeds 1..=N (8 unless given), which permute every
# family's constraints and the frame's contact pairs, on the reference engine and on the fast
# one, and a row says in how many it held. Prints the table in Markdown, then its running time.
# Usage: scripts/contact-checks.sh [N]   (the bunny row needs the shared meshes in ../shared/meshes)
set -euo pipefail
cd "$(dirname "$0")/.."
[ -n "${TETLAB:-}" ] || cargo build --release --quiet
tetlab=${TETLAB:-${CARGO_TARGET_DIR:-target}/release/tetlab}
n=${1:-8}
start=$(date +%s)

# check WHAT TEST ARGS...: one row. TEST is a Python expression over `frames` (the --json
# lines of one run, frame 0 first) that holds when the check does.
check() {
  local what=$1 test=$2
  shift 2
  local cells=()
  for engine in reference fast; do
    local held=0 notes=()
    for seed in $(seq 1 "$n"); do
      if "$tetlab" run "$@" --engine "$engine" --order-seed "$seed" --json | python3 -c '
import json, sys
frames = [json.loads(l) for l in sys.stdin]
body = lambda f, name: next(b for b in f["bodies"] if b["name"] == name)
ok, note = eval(sys.argv[1])
print(note, file=sys.stderr)
sys.exit(0 if ok else 1)' "$test" 2>/tmp/contact-check-note; then
        held=$((held + 1))
      fi
      notes+=("$(cat /tmp/contact-check-note)")
    done
    cells+=("$held of $n; $(printf '%s\n' "${notes[@]}" | sort -g | sed -n '1p;$p' | paste -sd ' ' | sed 's/ / to /')")
  done
  echo "| $what | ${cells[0]} | ${cells[1]} | \`tetlab run $*\` |"
}

echo "| check | reference engine | fast engine | command |"
echo "| --- | --- | --- | --- |"
# The upper cube's centre moves under 0.1 mm in 10 s, and no contact is ever closer than a
# tenth of the thickness (0.01 m).
check "a stack rests: the upper cube moves < 0.1 mm in 10 s, penetration < d/10 (drift, m)" '(
  sum((a - b) ** 2 for a, b in zip(body(frames[-1], "upper")["centre_of_mass"],
      body(frames[0], "upper")["centre_of_mass"])) ** 0.5 < 1e-4 and
  max(f["max_penetration"] for f in frames) < 1e-3,
  "%.1e" % sum((a - b) ** 2 for a, b in zip(body(frames[-1], "upper")["centre_of_mass"],
      body(frames[0], "upper")["centre_of_mass"])) ** 0.5)' \
  --scene assets/scenes/stacked-cubes.toml --constraints edges,volume,contact --frames 600
# Resting on the lower cube the upper's centre is at 1.26 m; through its top by d, at 1.24 m.
check "a cube thrown down at 8 m/s does not pass through another: its centre stays above 1.24 m (lowest, m)" '(
  min(body(f, "upper")["centre_of_mass"][1] for f in frames) > 1.24,
  "%.3f" % min(body(f, "upper")["centre_of_mass"][1] for f in frames))' \
  --scene assets/scenes/dropped-cube.toml --constraints edges,volume,contact --frames 20
# The energy account (elastic energy included) never rises above its lowest by more than 1 %
# of the scene's scale: the rise above the running lowest, largest of the run, J.
rise='(lambda totals: max(t - min(totals[:i + 1]) for i, t in enumerate(totals)))([f["energy_total"] + f["energy_taken_ground"] + f["energy_taken_damping"] for f in frames])'
check "contact gives no energy: two neo-Hookean cubes, one thrown onto the other's edge (largest rise, J, of 8033)" "(
  $rise < 0.01 * frames[0][\"energy_total\"], \"%.2e\" % $rise)" \
  --scene assets/scenes/two-cubes.toml --constraints neohookean,contact --frames 90
# Coulomb: tan 30° = 0.577. μ = 0.6 holds (moves < 1 mm in 1 s); μ = 0.3 slides
# ½ g (sin θ − μ cos θ) t² = 1.1781 m, to 1 % of ½ g sin θ t² = 2.4525 m.
moved='sum((a - b) ** 2 for a, b in zip(body(frames[-1], "block")["centre_of_mass"], body(frames[0], "block")["centre_of_mass"])) ** 0.5'
check "friction holds a block on a 30° ramp with μ = 0.6 (moved, m)" "($moved < 1e-3, \"%.1e\" % $moved)" \
  --scene assets/scenes/ramp.toml --constraints edges,volume,contact --friction 0.6 --frames 60
check "friction lets it slide with μ = 0.3, 1.1781 m in 1 s by Coulomb (slid, m)" "(abs($moved - 1.1781) < 0.0245, \"%.4f\" % $moved)" \
  --scene assets/scenes/ramp.toml --constraints edges,volume,contact --friction 0.3 --frames 60
# Self-contact: the upper leg of a soft hairpin sags onto the lower and rests there; no
# contact closer than a tenth of the thickness over 3 s, and some touching at the end.
check "a bar folded onto itself rests on itself: touching at the end, penetration < d/10 over 3 s (deepest, m)" '(
  frames[-1]["contacts"] > 0 and max(f["max_penetration"] for f in frames) < 1e-3,
  "%.1e" % max(f["max_penetration"] for f in frames))' \
  --scene assets/scenes/folded-bar.toml --constraints neohookean,contact --material E=1e5,nu=0.3 --frames 180
# Two bodies of their own stuff: a soft neo-Hookean cube (E = 0.1 MPa, 500 kg/m³, 0.6 m) on a
# block of rigid edges and volumes. Undamped it swings about its static sag; a column's centre
# sinks ρ g L² / 3E = 5.9 mm under its weight, and the mean over the last second is within a
# factor 2 of that (a coarse mesh whose feet friction holds); the block's centre moves < 0.1 mm.
sunk='(sum(body(frames[0], "soft")["centre_of_mass"][1] - body(f, "soft")["centre_of_mass"][1] for f in frames[-60:]) / 60)'
block='max(abs(body(f, "block")["centre_of_mass"][1] - body(frames[0], "block")["centre_of_mass"][1]) for f in frames)'
check "a soft body rests on a stiff one: its centre sinks within a factor 2 of ρgL²/3E = 5.9 mm, the block's < 0.1 mm, penetration < d/10 (sunk, m)" "(
  0.5 * 0.00589 < $sunk < 2 * 0.00589 and $block < 1e-4 and max(f[\"max_penetration\"] for f in frames) < 1e-3,
  \"%.4f\" % $sunk)" \
  --scene assets/scenes/soft-on-stiff.toml --constraints edges,volume,neohookean,contact --frames 180
if [ -f ../shared/meshes/bunny.node ]; then
  check "the bunny dropped on a ball gives no energy (largest rise, J, of 5733)" "(
    $rise < 0.01 * frames[0][\"energy_total\"], \"%.2e\" % $rise)" \
    --scene assets/scenes/bunny-on-ball.toml --constraints neohookean,contact --frames 150
fi
# Two armadillos 3 m tall, one dropped from half a metre onto the other's head: it knocks the
# other over and both come down on the ground at up to 10 m/s. No particle is ever closer than
# a tenth of the thickness to a surface of the other body or its own, over 2 s: at the defaults
# (one sweep of rigid edges and volumes, 100 substeps) and at 200 substeps.
if [ -f ../shared/meshes/armadillo_4k.node ]; then
  deepest='max(f["max_penetration"] for f in frames)'
  for substeps in 100 200; do
    check "two armadillos, one dropped on the other, $substeps substeps: penetration < d/10 over 2 s (deepest, m)" "(
      $deepest < 1e-3, \"%.1e\" % $deepest)" \
      --scene assets/scenes/two-armadillos.toml --constraints edges,volume,contact --substeps "$substeps" --frames 120
  done
fi
echo
echo "$(($(date +%s) - start)) s"
