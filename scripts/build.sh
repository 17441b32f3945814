#!/usr/bin/env bash
# Configure and build Rosin (dsp, lab, the plugin and its host, tests, benchmarks) into ./build.
# Used by demo.sh and test.sh. ROSIN_BUILD_PLUGIN=OFF skips JUCE for a fast dsp/lab loop.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DROSIN_BUILD_PLUGIN="${ROSIN_BUILD_PLUGIN:-ON}" "$@" > build-configure.log 2>&1 || { cat build-configure.log; exit 1; }
cmake --build build -j "$(nproc)"
