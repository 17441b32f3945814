#!/usr/bin/env bash
# Fuzz the HID descriptor parser, report decoder and bow mapper with libFuzzer (clang) under
# AddressSanitizer and UBSan. Usage: scripts/fuzz.sh [seconds, default 20] [build dir].
# CI runs it for 20 s (ctest, label hid); run it longer by hand: scripts/fuzz.sh 1800
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-20}
out=$(realpath -m "${2:-build/fuzz}")
mkdir -p "$out/corpus"
src=plugin/hid
clang++ -std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
  -I "$src/include" -I plugin/rt/include -I presets/lib/include \
  "$src/fuzz/FuzzHid.cpp" "$src/src/Descriptor.cpp" "$src/src/Mapping.cpp" presets/lib/src/Document.cpp -o "$out/fuzz-hid"
# Seeds: every real descriptor, wrapped in the input format with one all-zero report.
for f in tests/data/hid/*.rdesc.bin; do
  [[ -f "$f" ]] || continue
  n=$(stat -c %s "$f")
  { printf "\\x$(printf %02x $((n & 255)))\\x$(printf %02x $((n >> 8)))"; cat "$f"; printf '\x08\x01\x00\x00\x00\x00\x00\x00\x00'; } \
    > "$out/corpus/$(basename "$f").seed"
done
echo "fuzz: ${seconds}s on $(ls "$out/corpus" | wc -l) corpus files" >&2
"$out/fuzz-hid" -max_total_time="$seconds" -max_len=4200 -timeout=10 -print_final_stats=1 "$out/corpus" 2>&1 | tail -15
