#!/usr/bin/env bash
# Installed as a user installs it: the built VST3 and LV2 bundles are copied to a fresh HOME
# (~/.vst3, ~/.lv2), nothing points at the source tree (no source path inside the binaries, no
# ROSIN_PRESETS, another working directory), and then rosin-host and Ardour 7 (headless, Dummy
# backend, its default plugin paths) load them from there: the presets are listed and a note plays.
# Usage: installed-check.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(realpath "$1")
src=$(realpath "$2")
artefacts="$build/plugin/RosinPlugin_artefacts/Release"
host="$build/plugin/rosin-host"
home=$(mktemp -d)
trap 'rm -rf "$home"' EXIT
mkdir -p "$home/.vst3" "$home/.lv2"
cp -r "$artefacts/VST3/Rosin.vst3" "$home/.vst3/"
cp -r "$artefacts/LV2/Rosin.lv2" "$home/.lv2/"

fail() { echo "installed-check: $*" >&2; exit 1; }
for so in $(find "$home" -name '*.so'); do
  if strings "$so" | grep -qF "$src"; then fail "$so holds the source path $src"; fi
  if strings "$so" | grep -qF "$build"; then fail "$so holds the build path $build"; fi
done
echo "no source or build path inside the installed binaries"

cd /
for bundle in "$home/.vst3/Rosin.vst3" "$home/.lv2/Rosin.lv2"; do
  presets=$(env -u ROSIN_PRESETS HOME="$home" "$host" presets --plugin "$bundle")
  for name in violin viola cello double-bass; do
    grep -qx "$name" <<<"$presets" || fail "$bundle does not list the $name preset (got: $(echo $presets))"
  done
  env -u ROSIN_PRESETS HOME="$home" "$host" render --plugin "$bundle" --preset violin --events <(printf '0.0 90 45 64\n0.8 80 45 00\n') \
    --seconds 1.2 --out "$home/note.wav" --report "$home/report.json" 2>/dev/null
  peak=$(python3 -c "import json,sys; print(json.load(open('$home/report.json'))['peak'])")
  python3 -c "import sys; sys.exit(0 if $peak > 0.01 else 1)" || fail "$bundle: the note is silent (peak $peak)"
  echo "$(basename "$bundle") from $(dirname "$bundle"): presets $(echo $presets), a violin note peaks at $peak"
done

# Ardour finds bundles in ~/.lv2 and ~/.vst3 by itself, as on a user's machine.
cd "$src"
env -u ROSIN_PRESETS -u LV2_PATH HOME="$home" bash scripts/ardour-check.sh --installed "$home"
