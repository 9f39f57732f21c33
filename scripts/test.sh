#!/usr/bin/env bash
# Everything a fresh machine needs, then every check and test of tetlab:
# rustfmt and clippy (warnings are errors), then all tests of the workspace (unit, doc,
# end to end). Exits non-zero on the first failure.
set -euo pipefail
cd "$(dirname "$0")/.."

missing=()
for component in rustfmt clippy; do
  rustup component list --installed 2>/dev/null | grep -q "^$component" || missing+=("$component")
done
if [ ${#missing[@]} -gt 0 ]; then
  rustup component add "${missing[@]}"
fi

echo "== cargo fmt --check"
cargo fmt --all --check
echo "== cargo clippy --all-targets -- -D warnings"
cargo clippy --workspace --all-targets --locked -- -D warnings
echo "== cargo test --workspace"
cargo test --workspace --locked
