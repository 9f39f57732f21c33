#!/usr/bin/env bash
# Runs the benchmarks of docs/performance.md and prints their table in Markdown. Each row is one
# `tetlab bench` command, shown in the row, run three times; the row keeps the fastest run (this
# machine shares its cores, and the slower runs are other people's load, not tetlab's).
# Usage: scripts/bench.sh > /tmp/table.md   (needs the shared meshes in ../shared/meshes)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
tetlab=${CARGO_TARGET_DIR:-target}/release/tetlab
bunny=../shared/meshes/bunny.node

echo "| scene | tets | constraints | engine, threads | projections per frame | ms per frame | frames per second | ns per projection (by family) | bytes per tet | error at the end (by family) | command |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"

row() {
  local args="$*"
  for _ in 1 2 3; do "$tetlab" bench $args --json | tail -n 1; done | python3 -c '
import json, sys
args = sys.argv[1]
runs = [json.loads(line) for line in sys.stdin]
r = min(runs, key=lambda r: r["ms_per_frame"])
f = r["ns_per_projection_by_family"]
families = "" if f is None else " (" + ", ".join(
    "%s %.1f" % (k, v) for k, v in f.items() if v > 0) + ")"
e = r.get("relative_error")
errors = "—" if e is None else ", ".join(
    "%s %.1e" % (k, v) for k, v in e.items() if v is not None)
print("| %s | %d | %s | %s, %d | %d | %.3f | %.1f | %.1f%s | %.0f | %s | `tetlab bench %s` |" % (
    r["scene"], r["tets"], r["constraints"], r["solver"], r["threads"],
    r["projections_per_frame"], r["ms_per_frame"], r["frames_per_second"],
    r["ns_per_projection"], families, r["bytes_per_tet"], errors, args))
' "$args"
}

row --scene $bunny --frames 1000 --substeps 10
row --scene $bunny --frames 300 --engine reference --substeps 10
row --scene $bunny --frames 300 --constraints edges,height,volume --substeps 10
row --scene $bunny --frames 1000 --jacobi --substeps 10
row --scene cube --resolution 6 --frames 500 --substeps 10
row --scene cube --resolution 13 --frames 100 --substeps 10
row --scene cube --resolution 26 --frames 40 --substeps 10
row --scene cube --resolution 26 --frames 40 --threads 2 --substeps 10
row --scene cube --resolution 26 --frames 10 --constraints edges,height,volume --substeps 10
row --scene cube --resolution 26 --frames 40 --jacobi --substeps 10
row --scene cube --resolution 55 --frames 5 --warmup 1 --substeps 10
row --scene cube --resolution 55 --frames 5 --warmup 1 --threads 2 --substeps 10
row --scene cube --resolution 55 --frames 5 --warmup 1 --constraints edges,height,volume --substeps 10
row --scene $bunny --frames 300 --constraints edges,neohookean --substeps 10
row --scene $bunny --frames 300 --constraints height --substeps 10
row --scene $bunny --frames 300 --constraints none --constraint-file assets/constraints/height.toml --substeps 10
row --scene $bunny --frames 100 --engine reference --constraints height --substeps 10
row --scene $bunny --frames 100 --engine reference --constraints none --constraint-file assets/constraints/height.toml --substeps 10
