#!/usr/bin/env bash
# Writes the fonts of the web page, assets/fonts/web/: DejaVu Sans Mono and egui's Ubuntu Light,
# cut to the characters tetlab shows (Latin, Greek, punctuation, sub- and superscripts, number
# forms, arrows, mathematical operators, technical and geometric shapes) and without hinting
# (egui's rasteriser does not use it). The page carries these instead of egui's default fonts
# (Ubuntu Light, Hack, two emoji fonts: 0.78 MB gzipped) and the whole DejaVu Sans Mono
# (0.20 MB): 0.11 MB in all. The desktop keeps the full fonts. Needs fonttools (pip install
# fonttools); run it after changing the character ranges, and commit what it writes.
set -euo pipefail
cd "$(dirname "$0")/.."
egui_fonts=$(ls -d ~/.cargo/registry/src/*/epaint_default_fonts-0.37*/fonts | head -n 1)
out=assets/fonts/web
mkdir -p "$out"
pyftsubset assets/fonts/DejaVuSansMono.ttf --no-hinting \
  --unicodes="U+0020-024F,U+0370-03FF,U+2000-206F,U+2070-209F,U+2100-214F,U+2150-218F,U+2190-21FF,U+2200-22FF,U+2300-23FF,U+25A0-25FF,U+2600-26FF" \
  --output-file="$out/DejaVuSansMono-subset.ttf"
pyftsubset "$egui_fonts/Ubuntu-Light.ttf" --no-hinting \
  --unicodes="U+0020-024F,U+2000-206F,U+20A0-20CF,U+2100-214F" \
  --output-file="$out/Ubuntu-Light-subset.ttf"
cp "$egui_fonts/UFL.txt" "$out/LICENSE-Ubuntu-UFL.txt"
cp assets/fonts/LICENSE-DejaVu.txt "$out/LICENSE-DejaVu.txt"
ls -l "$out"
