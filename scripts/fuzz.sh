#!/usr/bin/env bash
# Runs every fuzz target of fuzz/ (cargo-fuzz on libFuzzer, on the stable toolchain), each seeded
# from real files: the meshes of ../shared/meshes (when present) and assets/meshes, the lessons
# of assets/lessons, the constraint files of assets/constraints, the scene files of
# assets/scenes, and recordings tetlab writes.
# Prints, per target, the executions, the time and the crashes; a crash's input is kept in
# fuzz/artifacts/TARGET/ and the run fails.
#
# Usage: scripts/fuzz.sh [--seconds S | --runs N] [TARGET...]
#   --seconds S   run each target for S seconds (default 60)
#   --runs N      run each target for N executions
#   TARGET        tetgen, gmsh_v22, gmsh_v41, lesson, rrd, constraint_file, scene_file
#                 (default: all)
# The corpus grows in $TETLAB_FUZZ_CORPUS (default /var/tmp/tetlab-fuzz-corpus), outside the
# repository, so later runs start where earlier ones stopped; the instrumented build lives in
# $TETLAB_FUZZ_TARGET (default /var/tmp/tetlab-fuzz-target), so later runs reuse it.
set -euo pipefail
cd "$(dirname "$0")/.."

limit=(-max_total_time=60)
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) limit=(-max_total_time="$2"); shift 2 ;;
    --runs) limit=(-runs="$2"); shift 2 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=(tetgen gmsh_v22 gmsh_v41 lesson rrd constraint_file scene_file)

# cargo-fuzz of a version that builds with this toolchain, when missing.
fuzz_version=0.13.1
if ! cargo fuzz --version 2>/dev/null | grep -q "$fuzz_version"; then
  echo "== installing cargo-fuzz $fuzz_version"
  cargo install --quiet --locked cargo-fuzz --version "$fuzz_version"
fi
# cargo-fuzz passes the compiler a few flags that stable rustc keeps for nightly; this lets the
# stable compiler take them (the coverage instrumentation itself is stable). No sanitizer: the
# targets check for panics, overflows (debug assertions are on) and allocations.
fuzz_env=(env RUSTC_BOOTSTRAP=1 CARGO_TARGET_DIR="${TETLAB_FUZZ_TARGET:-/var/tmp/tetlab-fuzz-target}")
build=(--sanitizer none --release --debug-assertions)

corpus_root="${TETLAB_FUZZ_CORPUS:-/var/tmp/tetlab-fuzz-corpus}"
seeds=$(mktemp -d)
trap 'rm -rf "$seeds"' EXIT
shared=../shared/meshes
gmsh_body() { sed '1,/^\$EndMeshFormat/d' "$1"; }
seed() {
  local target=$1 dir="$seeds/$1"
  mkdir -p "$dir"
  case "$target" in
    tetgen)
      for stem in assets/meshes/bipyramid "$shared/bunny" "$shared/armadillo_4k"; do
        [ -f "$stem.node" ] || continue
        { cat "$stem.node"; printf '\0'; cat "$stem.ele"; } >"$dir/$(basename "$stem")"
      done ;;
    gmsh_v22|gmsh_v41)
      local version=${target#gmsh_v}
      for mesh in "$shared"/*.msh; do
        [ -f "$mesh" ] && grep -q "^${version:0:1}\.${version:1:1} " "$mesh" || continue
        gmsh_body "$mesh" >"$dir/$(basename "$mesh")"
      done
      # A small mesh of this version, always there.
      if [ "$version" = 22 ]; then
        printf '$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n' >"$dir/tet"
      else
        printf '$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n' >"$dir/tet"
      fi ;;
    lesson)
      cp assets/lessons/*.toml "$dir/" ;;
    scene_file)
      cp assets/scenes/*.toml "$dir/" ;;
    constraint_file)
      cp assets/constraints/*.toml "$dir/"
      # The generator's inputs (fuzz/fuzz_targets/constraint_file.rs): NUL-separated segments,
      # N*TEXT repeating TEXT, for the deep and long files that once crashed the parser.
      local head='name = "g"\napplies_to = "edges"\n'
      printf "${head}"'value = "\00010000*(\0001\00010000*)\000"\n' >"$dir/gen-parentheses"
      printf "${head}"'value = "\00010000*abs(\0001\00010000*)\000"\n' >"$dir/gen-abs"
      printf "${head}"'value = "\00020000*-\0001\000"\n' >"$dir/gen-minus"
      printf "${head}"'value = "\00055000*p0.x + \0001\000"\n' >"$dir/gen-sum"
      printf "${head}"'define = "k = \00010000*(\0001\00010000*)\000"\nvalue = "k"\n' >"$dir/gen-define" ;;
    rrd)
      cargo run --quiet --locked -- record --scene tet --frames 2 --arrows none --quiet --out "$dir/tet.rrd" >/dev/null
      cargo run --quiet --locked -- record --scene cube --resolution 1 --frames 1 --quiet --out "$dir/cube.rrd" >/dev/null ;;
  esac
  echo "$dir"
}

echo "== building the fuzz targets"
"${fuzz_env[@]}" cargo fuzz build "${build[@]}"
failed=0
printf '%-16s %14s %9s %8s\n' target executions seconds crashes
for target in "${targets[@]}"; do
  corpus="$corpus_root/$target"
  mkdir -p "$corpus" "fuzz/artifacts/$target"
  log="$seeds/$target.log"
  started=$(date +%s.%N)
  status=0
  # -malloc_limit_mb: an allocation the input cannot justify is a crash (a damaged length field
  # that asks for terabytes). -rss_limit_mb and -timeout catch the rest.
  seeded=$(seed "$target")
  extra=()
  # A recording's first 16 KB hold its header and a dozen messages (each decoded as arrow): the
  # whole files, ten times as long, would make each run ten times as slow.
  [ "$target" = rrd ] && extra=(-max_len=16384)
  # Long enough for the generator's inputs to grow past libFuzzer's default of 4,096 bytes;
  # they stand for texts of up to 2 MB (see the target).
  [ "$target" = constraint_file ] && extra=(-max_len=65536)
  "${fuzz_env[@]}" cargo fuzz run "${build[@]}" "$target" "$corpus" "$seeded" -- \
    "${limit[@]}" "${extra[@]}" -malloc_limit_mb=1024 -rss_limit_mb=3072 -timeout=10 \
    -artifact_prefix="fuzz/artifacts/$target/" -print_final_stats=1 >"$log" 2>&1 || status=$?
  seconds=$(python3 -c "import time; print(f'{time.time() - $started:.0f}')")
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  crashes=$(find "fuzz/artifacts/$target" -type f | wc -l)
  printf '%-16s %14s %9s %8s\n' "$target" "${runs:-0}" "$seconds" "$crashes"
  if [ "$status" -ne 0 ] || [ "$crashes" -ne 0 ]; then
    failed=1
    echo "-- $target failed (status $status); the end of its log:" >&2
    tail -30 "$log" >&2
  fi
done
exit $failed
