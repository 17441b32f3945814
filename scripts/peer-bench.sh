#!/usr/bin/env bash
# Rosin's thermal voice beside STK Bowed and Faust's violins (../shared/bench/peers), several
# runs, each pinned to one core so every peer in a run shares it; prints each run and the
# median of Rosin / STK Bowed. A benchmark, not a test: it needs a quiet machine to mean much.
#
#   bash scripts/peer-bench.sh            # 3 runs of 10 s x 3 passes on the last core
#   RUNS=5 CORE=0 SECONDS_PER_PASS=20 bash scripts/peer-bench.sh
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
root=$PWD
peers="$root/../shared/bench/peers/run.sh"
[[ -f "$peers" ]] || { echo "peer-bench: $peers not found (the shared peer benchmark)" >&2; exit 1; }
[[ -x build/lab/rosin ]] || ROSIN_BUILD_PLUGIN=OFF bash scripts/build.sh
runs=${RUNS:-3}
core=${CORE:-$(($(nproc) - 1))}
seconds=${SECONDS_PER_PASS:-10}
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "peer-bench: RUNS must be a positive whole number, got '$runs'" >&2; exit 1; }
[[ "$core" =~ ^[0-9]+$ && "$core" -lt $(nproc) ]] || { echo "peer-bench: CORE must be 0..$(($(nproc) - 1)), got '$core'" >&2; exit 1; }

ratios=()
for ((run = 1; run <= runs; ++run)); do
  [[ -t 2 ]] && printf 'peer-bench: run %d of %d on core %d ...\r' "$run" "$runs" "$core" >&2
  out=$(OUR_BENCH="$root/build/lab/rosin bench --freq 440" BENCH_SECONDS="$seconds" BENCH_REPS=3 \
        taskset -c "$core" bash "$peers" 2>&1) || { echo "$out" >&2; exit 1; }
  stk=$(awk '$1 == "stk_bowed" {print $2}' <<<"$out")
  ours=$(awk '$1 == "ours" {print $2}' <<<"$out")
  [[ -n "$stk" && -n "$ours" ]] || { echo "$out" >&2; echo "peer-bench: no result lines" >&2; exit 1; }
  ratio=$(awk -v a="$ours" -v b="$stk" 'BEGIN {printf "%.3f", a / b}')
  ratios+=("$ratio")
  printf 'run %d: stk_bowed %s ns, rosin %s ns, ratio %s\n' "$run" "$stk" "$ours" "$ratio"
done
median=$(printf '%s\n' "${ratios[@]}" | sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}')
echo "median ratio rosin / stk_bowed: $median (goal <= 0.5)"
