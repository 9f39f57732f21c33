#!/usr/bin/env bash
# Everything a fresh machine needs, then every check and test of tetlab:
# rustfmt, clippy and rustdoc (warnings are errors), the workbench built as a web page and opened in
# headless Chromium, Rerun's own checker on a recording tetlab writes, all tests of the workspace
# (unit, doc, end to end, the abuse runs), then every fuzz target briefly. Exits non-zero on the
# first failure.
set -euo pipefail
cd "$(dirname "$0")/.."

# The workbench's screenless snapshot tests render with wgpu on Mesa's software Vulkan (lavapipe).
if ! dpkg -s mesa-vulkan-drivers >/dev/null 2>&1; then
  echo "== installing mesa-vulkan-drivers (software Vulkan for the snapshot tests)"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq mesa-vulkan-drivers >/dev/null
fi
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"

missing=()
for component in rustfmt clippy; do
  rustup component list --installed 2>/dev/null | grep -q "^$component" || missing+=("$component")
done
if [ ${#missing[@]} -gt 0 ]; then
  rustup component add "${missing[@]}"
fi

echo "== cargo fmt --check"
cargo fmt --all --check
(cd fuzz && cargo fmt --check)
echo "== cargo clippy --all-targets -- -D warnings"
cargo clippy --workspace --all-targets --locked -- -D warnings
echo "== cargo doc --no-deps (warnings are errors: every link in the docs resolves)"
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --locked
# The workbench as a web page, built and opened in headless Chromium (installs what it needs).
echo "== the web page (scripts/web-test.sh)"
scripts/web-test.sh
# Rerun's own checker on a recording tetlab writes (rerun-sdk of the same version as the crate).
rerun_version=0.36.3
venv="${TETLAB_RERUN_VENV:-/var/tmp/tetlab-rerun-$rerun_version}"
if ! "$venv/bin/rerun" --version 2>/dev/null | grep -q "$rerun_version"; then
  echo "== installing rerun-sdk $rerun_version into $venv"
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet "rerun-sdk==$rerun_version"
fi
"$venv/bin/rerun" analytics disable >/dev/null 2>&1 || true
scene=../shared/meshes/bunny.node
[ -f "$scene" ] || scene=ball
recording="$(mktemp -d)/check.rrd"
echo "== rerun rrd verify (a recording of $scene)"
cargo run --locked --quiet -- record --scene "$scene" --perturb flatten --gravity 10 \
  --constraints edges,height,volume --frames 60 --quiet --out "$recording"
"$venv/bin/rerun" rrd verify "$recording"
echo "== rerun rrd verify (a recording of two bodies in contact)"
cargo run --locked --quiet -- record --scene assets/scenes/stacked-cubes.toml \
  --constraints edges,volume,contact --frames 30 --quiet --out "$recording.contact.rrd"
"$venv/bin/rerun" rrd verify "$recording.contact.rrd"

if [ -d ../shared/meshes ]; then
  echo "== ../shared/meshes is here: the tests that read the reference meshes run"
else
  echo "== ../shared/meshes is absent: the tests that read the reference meshes skip (under CI=true they fail)"
fi
echo "== cargo test --workspace"
cargo test --workspace --locked

# Every fuzz target for a few seconds, so that they keep building and the easy breaks are found
# (scripts/fuzz.sh runs them for longer; docs/reliability.md).
echo "== fuzz targets (scripts/fuzz.sh --seconds 8)"
scripts/fuzz.sh --seconds 8
