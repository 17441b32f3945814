#!/usr/bin/env bash
# The engine, processor and HID tests under ThreadSanitizer (ctest label tsan), in build-tsan/:
# every cross-thread channel (engine hand-off, MIDI-learn tables, parameter and learn queues,
# HID events, the HID thread and its hot-plug watcher) exercised while audio runs. test.sh (and so CI) runs it after the main suite.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DROSIN_TSAN=ON -DROSIN_BUILD_PLUGIN=ON \
  -DROSIN_BUILD_BENCHMARKS=OFF > build-tsan-configure.log 2>&1 || { cat build-tsan-configure.log; exit 1; }
cmake --build build-tsan -j "$(nproc)" --target rosin_engine_tests rosin_processor_tests rosin_hid_tests
ctest --test-dir build-tsan --output-on-failure -L tsan -j "$(nproc)"
