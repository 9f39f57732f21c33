#!/usr/bin/env bash
# The browser end to end: builds the site (scripts/web.sh), serves it on localhost, opens it in
# headless Chromium (installed with apt when missing) and checks that the workbench started and
# drew the soft body: its "tetlab ready" line in the console, and a screenshot with the body's
# colour in it. The screenshot is kept at $TETLAB_WEB_SCREENSHOT (default: a temporary folder).
# Then drives the page through the DevTools protocol (below).
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v chromium >/dev/null; then
  echo "== installing chromium (headless browser for the web test)"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
fi
work=$(mktemp -d)
scripts/web.sh "$work/site"

port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
python3 -m http.server --bind 127.0.0.1 --directory "$work/site" "$port" >/dev/null 2>&1 &
server=$!
trap 'kill $server 2>/dev/null || true' EXIT
sleep 1

# Opens the page at address suffix $1 (what it is: $2) in headless Chromium, screenshots it into
# $3, and checks that it said "tetlab ready" and shows the soft body's colour.
open_and_look() {
  local suffix=$1 what=$2 shot=$3 log="$work/chromium-$4.log"
  echo "== opening http://127.0.0.1:$port/$suffix ($what) in headless chromium"
  chromium --headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking \
    --disable-component-update --disable-sync --disable-quic --enable-unsafe-swiftshader \
    --user-data-dir="$work/profile-$4" --window-size=1280,800 --virtual-time-budget=15000 \
    --enable-logging=stderr --v=0 --screenshot="$shot" "http://127.0.0.1:$port/$suffix" \
    >"$log" 2>&1 || true
  if ! grep -q "tetlab ready" "$log"; then
    echo "$what did not say \"tetlab ready\"; the browser's console:" >&2
    grep -i "console\|error" "$log" | tail -20 >&2 || true
    exit 1
  fi
  grep -o 'tetlab: drawing with [^"]*\|tetlab ready[^"]*' "$log" | head -2
  local body
  body=$(python3 scripts/png_colour_count.py "$shot" 150 180 210)
  echo "screenshot $shot: $body pixels of the body's colour"
  if [ "$body" -lt 20000 ]; then
    echo "the screenshot of $what does not show the soft body" >&2
    exit 1
  fi
  echo "$what OK"
}
open_and_look "" "the page" "${TETLAB_WEB_SCREENSHOT:-$work/web.png}" simd
# The build without SIMD, which the page loads where a browser rejects WebAssembly SIMD: forced
# with ?nosimd, it starts and draws the body too.
open_and_look "?nosimd" "the page's build without SIMD" "$work/web-nosimd.png" nosimd

# Then driven as a user would (tests/web/drive.mjs: puppeteer-core from the npm registry, against
# Debian's chromium; no browser is downloaded): a tet dragged inside out, Space, M, a lesson and a
# Gmsh mesh dropped, a broken file dropped, each exercise graded (a wrong answer, then a right
# one), lesson 6 on the fetched bunny, then every step of every built-in lesson with its checks
# (TETLAB_WEB_LESSONS=0 leaves that last part out); the page's state read after each step, one
# screenshot per step kept in $TETLAB_WEB_SHOTS (default: a temporary folder).
if ! command -v npm >/dev/null; then
  echo "== installing Node.js and npm (for the driven test)"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq nodejs npm >/dev/null
fi
echo "== driving the page (tests/web/drive.mjs)"
npm ci --prefix tests/web --no-audit --no-fund --silent
node tests/web/drive.mjs "http://127.0.0.1:$port/" "${TETLAB_WEB_SHOTS:-$work/shots}" .
