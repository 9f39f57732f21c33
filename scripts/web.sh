#!/usr/bin/env bash
# Builds the workbench as a static web page: the folder it writes (site/ by default, or $1) can be
# served by any static file server, e.g. `python3 -m http.server -d site 8000`.
# Two builds: with WebAssembly SIMD (simd128: the fast engine's lanes are SIMD registers), at the
# top of the folder, and without it in nosimd/, which the page loads where the browser's
# WebAssembly.validate rejects SIMD (web/index.html; `?nosimd` forces it, for tests).
# Installs what it needs when missing: the wasm32 target (rustup), wasm-bindgen-cli of the
# version in Cargo.lock (cargo install) and, with TETLAB_WASM_OPT=1, binaryen's wasm-opt (the npm
# registry's `binaryen`, in $TETLAB_WEB_CACHE, default ~/.cache/tetlab-web), whose result is cached
# there by the hash of its input. Prints the size of each .wasm, plain and gzipped.
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

target="${CARGO_TARGET_DIR:-target}"
mkdir -p "$out/nosimd"
# The SIMD build in a target folder of its own: its flags differ, and sharing one would rebuild
# every crate at each switch.
echo "== building the workbench for wasm32-unknown-unknown, with SIMD (simd128)"
CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUSTFLAGS="-C target-feature=+simd128" \
  cargo build --quiet --locked --profile web --target wasm32-unknown-unknown -p tetlab --bin tetlab \
  --target-dir "$target/simd128"
wasm-bindgen --target web --no-typescript --remove-name-section --remove-producers-section --out-dir "$out" \
  "$target/simd128/wasm32-unknown-unknown/web/tetlab.wasm"
echo "== building the workbench for wasm32-unknown-unknown, without SIMD (the fallback)"
cargo build --quiet --locked --profile web --target wasm32-unknown-unknown -p tetlab --bin tetlab
wasm-bindgen --target web --no-typescript --remove-name-section --remove-producers-section --out-dir "$out/nosimd" \
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
# The scene files the built-in lessons name (lesson 14's stacked cubes, `../scenes/NAME.toml`),
# from assets/scenes, beside them: the page fetches them from meshes/ too.
for name in $(sed -n 's|^scene = "\.\./scenes/\([^"]*\)".*|\1|p' assets/lessons/*.toml | sort -u); do
  mkdir -p "$out/meshes"
  cp "assets/scenes/$name" "$out/meshes/$name"
  echo "== placed assets/scenes/$name in $out/meshes/"
done

# Binaryen's optimiser (-Oz) with TETLAB_WASM_OPT=1, from the npm registry's `binaryen` package
# (its JavaScript build runs on the machine's Node.js; Debian 12's binaryen 108 is too old for
# wasm-bindgen's externref table: "WebAssembly.Table.set(): Argument 1 is invalid"). It takes
# about 1.5 minutes a build here, so its output is kept in the cache under the hash of its input
# and an unchanged build is not optimised again. It is off by default: it makes the .wasm 6 %
# smaller but the gzipped page, what a browser downloads, 0.2 % larger (docs/performance.md).
binaryen_version=132.0.0
cache="${TETLAB_WEB_CACHE:-$HOME/.cache/tetlab-web}"
optimise() {
  local wasm=$1
  if [ "${TETLAB_WASM_OPT:-0}" != 1 ]; then
    echo "== wasm-opt left out (TETLAB_WASM_OPT=1 runs it)"
    return
  fi
  if ! command -v npm >/dev/null; then
    echo "== installing Node.js and npm (for binaryen's wasm-opt)"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq nodejs npm >/dev/null
  fi
  local opt="$cache/binaryen-$binaryen_version/node_modules/.bin/wasm-opt"
  if [ ! -x "$opt" ]; then
    echo "== installing binaryen $binaryen_version from the npm registry into $cache"
    mkdir -p "$cache/binaryen-$binaryen_version"
    npm install --silent --no-audit --no-fund --prefix "$cache/binaryen-$binaryen_version" \
      "binaryen@$binaryen_version" >/dev/null
  fi
  local key
  key=$(sha256sum "$wasm" | cut -c1-32)
  if [ ! -f "$cache/$key.wasm" ]; then
    echo "== wasm-opt -Oz (binaryen $binaryen_version) on $wasm"
    "$opt" -Oz --enable-bulk-memory --enable-nontrapping-float-to-int --enable-sign-ext \
      --enable-mutable-globals --enable-reference-types --enable-multivalue --enable-simd \
      "$wasm" -o "$cache/$key.wasm.partial"
    mv "$cache/$key.wasm.partial" "$cache/$key.wasm"
  else
    echo "== wasm-opt: $wasm unchanged, its optimised build taken from $cache"
  fi
  cp "$cache/$key.wasm" "$wasm"
}
for wasm in "$out/tetlab_bg.wasm" "$out/nosimd/tetlab_bg.wasm"; do
  optimise "$wasm"
  bytes=$(stat -c %s "$wasm")
  gzipped=$(gzip -9 -c "$wasm" | wc -c)
  echo "wrote $wasm: $bytes bytes ($gzipped gzipped)"
done
echo "serve it with: python3 -m http.server -d $out 8000"
