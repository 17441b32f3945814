#!/usr/bin/env bash
# Install, build and run every test except the `long` soak runs (run those with: ctest --test-dir build -L long),
# then the engine, processor and HID tests again under ThreadSanitizer (scripts/tsan.sh, label tsan).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
ctest --test-dir build --output-on-failure -LE "long|tsan" -j "$(nproc)"
bash scripts/tsan.sh
