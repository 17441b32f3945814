#!/usr/bin/env bash
# The main job: install, build, then into ./out: the demo MIDI phrase played by the instrument
# (the built plugin in the headless host), a bowing-gesture phrase on one string, a Guettler
# stroke (WAV + CSV in newtons) and a Guettler diagram (PNG + CSV/JSON).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p out
./build/plugin/rosin-host render --midi presets/midi/demo-phrase.mid --preset cello --out out/demo-phrase.wav
# One short phrase per articulation (keyswitches choose them; legato and the mute are parameters).
mkdir -p out/articulations
for f in presets/midi/articulations/*.mid; do
  name=$(basename "$f" .mid)
  case "$name" in
    legato) ./build/plugin/rosin-host render --plugin build/plugin/RosinPlugin_artefacts/Release/VST3/Rosin.vst3 \
              --midi "$f" --preset violin --set legato=@1 --out "out/articulations/$name.wav" ;;
    *) ./build/plugin/rosin-host render --midi "$f" --preset violin --out "out/articulations/$name.wav" ;;
  esac
done
./build/plugin/rosin-host render --plugin build/plugin/RosinPlugin_artefacts/Release/VST3/Rosin.vst3 \
  --midi presets/midi/articulations/detache.mid --preset violin --set mute=@1 --out out/articulations/sordino.wav
./build/lab/rosin render --gesture-file presets/gestures/demo-phrase.csv --sample-rate 48000 --listen \
  --out out/gesture-phrase
./build/lab/rosin render --model enhanced --gesture guettler --force 1.0 --accel 1.0 --duration 0.3 \
  --out out/guettler-stroke
./build/lab/rosin guettler --model thermal --fit wg --variants 5 --out out/guettler-thermal
./build/lab/rosin render --gesture constant --force 1.0 --speed 0.1 --duration 1 --sample-rate 48000 --views \
  --out out/steady-stroke -q
echo "demo: listen to out/demo-phrase.wav (the cello plays presets/midi/demo-phrase.mid) and out/articulations/*.wav;"
echo "      look at out/guettler-thermal.png (data beside it); out/gesture-phrase.wav is one string under a"
echo "      bowing gesture, out/guettler-stroke.{wav,csv} one stroke in newtons; out/steady-stroke-views.png the"
echo "      plugin window's live views for a steady stroke; rosin figures -o out/figures draws the set"
