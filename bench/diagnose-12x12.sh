#!/usr/bin/env bash
# Benchmark of `rosin diagnose` on a 12x12 set (issue goal: under 2 minutes per effect-search
# round on a 2-core machine). Prints wall time, rounds and simulations per second.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
./build/lab/rosin synth-data --effect hertzian_contact --grid 12 --seed 77 -q -o "$work/set"
start=$(date +%s.%N)
./build/lab/rosin diagnose "$work/set" -o "$work/out" | tee "$work/log"
end=$(date +%s.%N)
rounds=$(grep -o '^round [0-9]*' "$work/log" | sort -u | wc -l)
sims=$(grep -o '[0-9]* simulations' "$work/log" | cut -d' ' -f1)
awk -v s="$start" -v e="$end" -v r="$rounds" -v n="$sims" \
  'BEGIN { w = e - s; printf "diagnose 12x12: %.1f s wall, %d rounds (%.1f s per round), %d simulations, %.0f simulations/s\n", w, r, w / r, n, n / w }'
