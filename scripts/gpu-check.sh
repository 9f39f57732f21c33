#!/usr/bin/env bash
# The GPU engine on a machine with a GPU, in one go (docs/performance.md, "The GPU engine"):
# builds tetlab, runs the GPU engine's tests, then prints one table of `tetlab bench` rows: the
# 20k, 100k and 1M blocks at 10 and 100 substeps on the GPU engine and on the fast engine (every
# core of this machine), the bunny and the armadillo (when ../shared/meshes is beside the clone),
# and `bench --workbench` on the GPU engine. Meant to finish within 8 minutes on a datacenter GPU.
#
#   scripts/gpu-check.sh            # the full table
#   QUICK=1 scripts/gpu-check.sh    # small blocks and few frames: checks the script itself on a
#                                   # software adapter (lavapipe), in a few minutes
#
# TETLAB=path uses that binary instead of building one (its tests are then not run).
set -euo pipefail
cd "$(dirname "$0")/.."

if [[ -z "${TETLAB:-}" ]]; then
    echo "== building tetlab (release)"
    cargo build --release --locked --bin tetlab
    echo "== the GPU engine's tests"
    cargo test --release --locked -p tetlab-core --features gpu --test gpu_engine
    TETLAB=${CARGO_TARGET_DIR:-target}/release/tetlab
fi

if [[ -n "${QUICK:-}" ]]; then
    blocks=(4 6 8)
    names=("small" "medium" "large")
    frames=2
else
    # 20,250, 105,456 and 998,250 tets.
    blocks=(15 26 55)
    names=("20k" "100k" "1M")
    frames=20
fi

# The GPU engine, and the fast one on every core of this machine.
engines=("--engine gpu" "--engine fast --threads $(nproc)")

table=$(mktemp)
trap 'rm -f "$table"' EXIT

# One row: a label, then `tetlab bench` options; the JSON report's figures go into the table.
row() {
    local label=$1
    shift
    local json
    if ! json=$("$TETLAB" bench "$@" --json 2>/dev/null | tail -n 1); then
        printf '%s\tfailed: tetlab bench %s\n' "$label" "$*" >>"$table"
        return
    fi
    python3 - "$label" "$json" >>"$table" <<'EOF'
import json, sys
label, r = sys.argv[1], json.loads(sys.argv[2])
dispatches = r.get("dispatches_per_frame")
per = r.get("us_per_dispatch")
print("\t".join([
    label,
    r["solver"] + (" on " + r["gpu"] if r.get("gpu") else f", {r['threads']} threads"),
    str(r["tets"]),
    str(r["substeps"]),
    f"{r['ms_per_frame']:.2f}",
    f"{r['projections_per_frame'] * r['frames_per_second']:.3g}",
    str(dispatches) if dispatches is not None else "-",
    f"{per:.2f}" if per is not None else "-",
]))
EOF
}

echo "== the table (each row: tetlab bench ... --frames $frames)"
for k in 0 1 2; do
    n=${blocks[$k]}
    for substeps in 10 100; do
        for engine in "${engines[@]}"; do
            # shellcheck disable=SC2086
            row "block ${names[$k]} (cube $n)" $engine --scene cube --resolution "$n" \
                --constraints edges,volume --substeps "$substeps" --frames "$frames" --warmup 2
        done
    done
done
for mesh in bunny.node armadillo_4k.node; do
    path=../shared/meshes/$mesh
    if [[ -f $path ]]; then
        for engine in "${engines[@]}"; do
            # shellcheck disable=SC2086
            row "${mesh%.node}" $engine --scene "$path" \
                --constraints edges,height,volume --frames "$frames" --warmup 2
        done
    else
        printf '%s\tskipped: no %s\n' "${mesh%.node}" "$path" >>"$table"
    fi
done

{
    printf 'scene\tengine\ttets\tsubsteps\tms a frame\tprojections a second\tdispatches a frame\tus a dispatch\n'
    cat "$table"
} | column -t -s $'\t'

echo "== bench --workbench on the GPU engine"
"$TETLAB" bench --workbench --engine gpu --scene cube --resolution "${blocks[0]}" \
    --constraints edges,volume --frames "$frames" --warmup 2
