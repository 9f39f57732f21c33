#!/usr/bin/env bash
# Builds the workbench as a static web page: the folder it writes (site/ by default, or $1) can be
# served by any static file server, e.g. `python3 -m http.server -d site 8000`.
# Installs what it needs when missing: the wasm32 target (rustup) and wasm-bindgen-cli of the
# version in Cargo.lock (cargo install). Runs wasm-opt where the machine has it. Prints the size of
# the .wasm, plain and gzipped.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-site}"

rustup target list --installed | grep -q '^wasm32-unknown-unknown$' ||
  rustup target add wasm32-unknown-unknown
version=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/[^0-9.]/, ""); print; exit }' Cargo.lock)
if ! wasm-bindgen --version 2>/dev/null | grep -q " $version\$"; then
  echo "== installing wasm-bindgen-cli $version"
  cargo install --quiet wasm-bindgen-cli --version "$version"
fi

echo "== building the workbench for wasm32-unknown-unknown"
cargo build --quiet --locked --profile web --target wasm32-unknown-unknown -p tetlab --bin tetlab
target="${CARGO_TARGET_DIR:-target}"
mkdir -p "$out"
wasm-bindgen --target web --no-typescript --remove-name-section --remove-producers-section --out-dir "$out" \
  "$target/wasm32-unknown-unknown/web/tetlab.wasm"
cp web/index.html "$out/index.html"

# The meshes the built-in lessons name in ../shared/meshes (lesson 6's bunny: a .node and its
# .ele), copied beside the page when that folder is beside the repository; never committed. The
# page fetches them from meshes/ (app/src/web.rs); without them it greys those lessons out.
rm -rf "$out/meshes"
for name in $(sed -n 's|^scene = ".*shared/meshes/\([^"]*\)".*|\1|p' assets/lessons/*.toml | sort -u); do
  case "$name" in
    *.node | *.ele) files="${name%.*}.node ${name%.*}.ele" ;;
    *) files="$name" ;;
  esac
  for file in $files; do
    if [ -f "../shared/meshes/$file" ]; then
      mkdir -p "$out/meshes"
      cp "../shared/meshes/$file" "$out/meshes/$file"
      echo "== placed ../shared/meshes/$file in $out/meshes/"
    else
      echo "== ../shared/meshes/$file is not here: the lessons on it are greyed out in the page"
    fi
  done
done

wasm="$out/tetlab_bg.wasm"
# Binaryen's optimiser, where the machine has one that understands wasm-bindgen's externref
# table (binaryen 116 and later: `cargo install wasm-opt`). Debian 12's binaryen (108) breaks it:
# the page then fails with "WebAssembly.Table.set(): Argument 1 is invalid".
opt_version=$(wasm-opt --version 2>/dev/null | grep -o 'version [0-9]*' | grep -o '[0-9]*' || true)
if [ -n "$opt_version" ] && [ "$opt_version" -ge 116 ]; then
  echo "== wasm-opt -Oz (binaryen $opt_version)"
  wasm-opt -Oz --enable-bulk-memory --enable-nontrapping-float-to-int --enable-sign-ext \
    --enable-mutable-globals --enable-reference-types --enable-multivalue "$wasm" -o "$wasm.opt"
  mv "$wasm.opt" "$wasm"
else
  echo "== no wasm-opt of binaryen 116 or later (found: ${opt_version:-none}): the page is not optimised further"
fi
bytes=$(stat -c %s "$wasm")
gzipped=$(gzip -9 -c "$wasm" | wc -c)
echo "wrote $out: tetlab_bg.wasm $bytes bytes ($gzipped gzipped); serve it with: python3 -m http.server -d $out 8000"
