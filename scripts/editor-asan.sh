#!/usr/bin/env bash
# The editor tests (open/close while audio runs, live views, scaling) built with AddressSanitizer
# and LeakSanitizer, in their own build tree (build-asan-ui). A full JUCE build: several minutes.
# Usage: scripts/editor-asan.sh            (ctest runs it under the `long` label too)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${ROSIN_ASAN_BUILD:-$root/build-asan-ui}"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DROSIN_BUILD_PLUGIN=ON -DROSIN_EDITOR_ASAN=ON \
  -DCMAKE_CXX_FLAGS="-fsanitize=address -fno-omit-frame-pointer" -DCMAKE_C_FLAGS="-fsanitize=address -fno-omit-frame-pointer" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address" >/dev/null
cmake --build "$build" --target rosin_editor_tests -j"$(nproc)"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$root/tests/lsan.supp:print_suppressions=0"
xvfb-run -a -s "-screen 0 1920x1200x24" "$build/tests/rosin_editor_tests"
echo "[editor-asan] clean: no AddressSanitizer error, no leak"
