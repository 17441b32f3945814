#!/usr/bin/env bash
# The main job: install, build, render the demo phrase (WAV), a Guettler stroke (WAV + CSV in
# newtons) and a Guettler diagram (PNG + CSV/JSON) into ./out.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p out
./build/lab/rosin render --gesture-file presets/gestures/demo-phrase.csv --sample-rate 48000 --listen \
  --out out/demo-phrase
./build/lab/rosin render --model enhanced --gesture guettler --force 1.0 --accel 1.0 --duration 0.3 \
  --out out/guettler-stroke
./build/lab/rosin guettler --model thermal --fit wg --variants 5 --out out/guettler-thermal
echo "demo: listen to out/demo-phrase.wav; look at out/guettler-thermal.png (data beside it);"
echo "      out/guettler-stroke.{wav,csv} is one stroke in newtons; rosin figures -o out/figures draws the whole set"
