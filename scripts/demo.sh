#!/usr/bin/env bash
# The main job: install, build, and render the demo phrase (WAV for listening, WAV in newtons
# and a CSV of every simulated quantity) into ./out.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p out
./build/lab/rosin render --gesture-file presets/gestures/demo-phrase.csv --sample-rate 48000 --listen \
  --out out/demo-phrase
./build/lab/rosin render --model enhanced --gesture guettler --force 1.0 --accel 1.0 --duration 0.3 \
  --out out/guettler-stroke
echo "demo: listen to out/demo-phrase.wav; out/guettler-stroke.{wav,csv} is one Guettler stroke in newtons"
