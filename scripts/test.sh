#!/usr/bin/env bash
# Install, build and run every test except the `long` soak runs (run those with: ctest --test-dir build -L long),
# then the engine, processor and HID tests again under ThreadSanitizer (scripts/tsan.sh, label tsan).
# Each step prints how long it took, so a slow CI run shows where its time went.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
step() { # step NAME COMMAND...
  local name=$1 start=$SECONDS; shift
  "$@"
  echo "== $name: $((SECONDS - start)) s (total $SECONDS s)"
}
step "install dependencies" bash scripts/install-deps.sh
step "build" bash scripts/build.sh
step "tests" ctest --test-dir build --output-on-failure -LE "long|tsan" -j "$(nproc)"
step "ThreadSanitizer build and tests" bash scripts/tsan.sh
