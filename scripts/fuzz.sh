#!/usr/bin/env bash
# Fuzz what reads bytes from outside with libFuzzer (clang) under AddressSanitizer and UBSan:
#   hid      HID descriptor parser, report decoder and bow mapper, with every quirk set
#   mapping  HidMapping::fromJson (controller files and the HID maps inside saved sessions)
#   state    the plugin's state reader (what a host hands setStateInformation)
# Usage: scripts/fuzz.sh [seconds per target, default 20] [build dir] [runs per target]
# CI runs 20 s per target (ctest hid_fuzz_bounded); the long run (ctest label long,
# hid_fuzz_long) asks for 10^6 executions of each. Exit status: non-zero on any crash.
set -euo pipefail
shopt -s inherit_errexit # a failed compile inside $(object ...) stops the script too
cd "$(dirname "$0")/.."
seconds=${1:-20}
out=$(realpath -m "${2:-build/fuzz}")
runs=${3:--1}
mkdir -p "$out"
# Line tables are all a crash report needs (full debug info costs a fifth more compile time).
flags=(-std=c++20 -O1 -gline-tables-only -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined)
objflags=(-std=c++20 -O1 -gline-tables-only -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined)
inc=(-I plugin/hid/include -I plugin/rt/include -I presets/lib/include -I plugin/engine/include -I dsp/include -I plugin/src)
juce=/usr/share/juce/modules
juce_defs=(-DJUCE_GLOBAL_MODULE_SETTINGS_INCLUDED=1 -DJUCE_STANDALONE_APPLICATION=1 -DNDEBUG=1 -I "$juce")

# Each of our sources compiled once per run and linked into every target that needs it (the HID
# sources go into all three).
object() { # object SOURCE [extra flags...] -> prints the object's path
  local src=$1; shift
  local obj="$out/obj/${src//\//_}.o"
  mkdir -p "$out/obj"
  clang++ "${objflags[@]}" "${inc[@]}" "$@" -c "$src" -o "$obj"
  echo "$obj"
}
hid_obj=()
for src in plugin/hid/src/Descriptor.cpp plugin/hid/src/Mapping.cpp plugin/hid/src/Devices.cpp presets/lib/src/Document.cpp; do
  hid_obj+=("$(object "$src")")
done
hid_main=$(object plugin/fuzz/FuzzHid.cpp)
mapping_main=$(object plugin/fuzz/FuzzMappingJson.cpp)
clang++ "${flags[@]}" "$hid_main" "${hid_obj[@]}" -o "$out/fuzz-hid"
clang++ "${flags[@]}" "$mapping_main" "${hid_obj[@]}" -o "$out/fuzz-mapping"
# The state reader needs juce_core and nothing else of JUCE (its object takes longest to build).
if [[ ! -f "$out/juce_core.o" || "$juce/juce_core/juce_core.cpp" -nt "$out/juce_core.o" ]]; then
  clang++ "${objflags[@]}" "${juce_defs[@]}" -DJUCE_USE_CURL=0 -c "$juce/juce_core/juce_core.cpp" -o "$out/juce_core.o"
fi
state_obj=()
for src in plugin/fuzz/FuzzState.cpp plugin/src/StateFormat.cpp plugin/engine/src/Parameters.cpp; do
  state_obj+=("$(object "$src" "${juce_defs[@]}")")
done
clang++ "${flags[@]}" "${state_obj[@]}" "${hid_obj[@]}" "$out/juce_core.o" -lz -lpthread -ldl -o "$out/fuzz-state"

# Seeds: every real descriptor (with each device choice), the shipped controller maps, and the
# saved states kept under tests/data/state (their inner XML).
mkdir -p "$out/corpus-hid" "$out/corpus-mapping" "$out/corpus-state"
for f in tests/data/hid/*.rdesc.bin; do
  n=$(stat -c %s "$f")
  for choice in 0 1 10 13; do
    { printf "\\x$(printf %02x $choice)\\x$(printf %02x $((n & 255)))\\x$(printf %02x $((n >> 8)))"; cat "$f"; printf '\x08\x01\x00\x00\x00\x00\x00\x00\x00'; } \
      > "$out/corpus-hid/$(basename "$f").$choice.seed"
  done
done
cp presets/controllers/*.json "$out/corpus-mapping/"
for f in tests/data/state/*.state; do
  { printf '\x01'; python3 tests/data/state/juce-state.py "$f"; } > "$out/corpus-state/$(basename "$f").seed"
done

status=0
for target in hid mapping state; do
  log="$out/fuzz-$target.log"
  if "$out/fuzz-$target" -max_total_time="$seconds" -runs="$runs" -max_len=4200 -timeout=10 -artifact_prefix="$out/$target-" -print_final_stats=1 \
       "$out/corpus-$target" > "$log" 2>&1; then
    echo "fuzz $target: $(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$') executions, 0 crashes"
  else
    echo "fuzz $target: FAILED (see $log)"; tail -30 "$log"; status=1
  fi
done
exit $status
