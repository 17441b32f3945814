#!/usr/bin/env bash
# Real-DAW check: Ardour 7 (ardour7-lua, Dummy backend, no display, no sound card) loads the
# BUILT Rosin LV2 and VST3 as the instrument of a MIDI track, plays a note and reads the meter.
# lilv (lv2ls/lv2info) must see and validate the LV2 bundle. Used by scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
# With --installed HOME the bundles are read from HOME/.lv2 and HOME/.vst3 (a user's install)
# and Ardour searches its default paths instead of being told where.
installed=""
if [[ "${1:-}" == "--installed" ]]; then
  installed=$(realpath "$2")
  lv2="$installed/.lv2"
  vst3="$installed/.vst3"
else
  artefacts=$(realpath "${1:-build/plugin/RosinPlugin_artefacts/Release}")
  lv2="$artefacts/LV2"
  vst3="$artefacts/VST3"
fi
[[ -d "$lv2/Rosin.lv2" && -d "$vst3/Rosin.vst3" ]] || { echo "ardour-check: no Rosin bundles in $lv2 and $vst3" >&2; exit 1; }

echo "== lilv"
LV2_PATH="$lv2" lv2ls | grep -qx "http://rosin-synth.org/plugins/rosin" || { echo "lv2ls does not list Rosin" >&2; exit 1; }
info=$(LV2_PATH="$lv2" lv2info http://rosin-synth.org/plugins/rosin)
echo "$info" | grep -E "^\s+Name:|Binary:" | head -2
ports=$(echo "$info" | grep -c "^	Port ")
echo "lv2info: $ports ports"
[[ $ports -ge 3 ]] || { echo "lv2info: too few ports" >&2; exit 1; }

echo "== Ardour 7 (Dummy backend)"
command -v ardour7-lua >/dev/null || { echo "ardour7-lua missing (package ardour)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Ardour finds VST3 plugins through its scanner's cache, as a DAW user's first scan would.
# It trusts a cache entry only when it is newer than the module by a whole second (it compares
# st_mtime in seconds), so a scan in the same second as the install is stale and the plugin is
# not listed: scan only once the clock has left the module's second.
module=$(find "$vst3/Rosin.vst3/Contents" -name 'Rosin.so' | head -1)
while (( $(date +%s) <= $(stat -c %Y "$module") )); do sleep 0.1; done
HOME="${installed:-$HOME}" LD_LIBRARY_PATH=/usr/lib/ardour7 /usr/lib/ardour7/ardour-vst3-scanner -q -f "$vst3/Rosin.vst3"
if [[ -n "$installed" ]]; then
  ROSIN_ARDOUR_SESSION="$work/session" HOME="$installed" \
    timeout 180 ardour7-lua scripts/ardour/check-rosin.lua 2>&1 | grep -v "No synth for midi-audition" | tee "$work/log"
else
  ROSIN_ARDOUR_SESSION="$work/session" LV2_PATH="$lv2" VST3_PATH="$vst3" \
    timeout 180 ardour7-lua scripts/ardour/check-rosin.lua 2>&1 | grep -v "No synth for midi-audition" | tee "$work/log"
fi
grep -q "ardour check passed" "$work/log"
