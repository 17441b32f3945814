#!/usr/bin/env bash
# The one list of Debian 12 packages Rosin needs. README and .ci/run both call this script.
# Run as root on a fresh Debian 12 machine; it is idempotent and quick when all is installed.
set -euo pipefail

# Core build + dsp/lab + tests + benchmarks (always needed).
CORE_PKGS=(
  build-essential cmake ninja-build pkg-config git
  libsndfile1-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev libtbb-dev
  libcairo2-dev fonts-dejavu-core          # figures (PNG) drawn by lab/
  libopenmpi-dev openmpi-bin               # Guettler sweeps over several processes/machines
  libnlopt-cxx-dev                         # fitting model extensions in diagnosis
  libeigen3-dev                            # linear algebra in the lab: covariances of fitted parameters
  # The instrument: JUCE 7.0.5 from Debian (its -dev dependencies come with it), LV2 headers,
  # JACK for the Standalone, and the checks a DAW user's machine would run.
  juce-modules-source lv2-dev libjack-jackd2-dev
  lilv-utils                               # lv2ls / lv2info see the built LV2
  ardour                                   # ardour7-lua: a real DAW loads VST3 and LV2 headless
  xvfb xauth x11-utils                     # the Standalone needs an X display
  jackd2 xdotool imagemagick               # editor test: JACK dummy audio, a click on its keyboard, screenshots
  libhidapi-dev libusb-1.0-0-dev           # HID controllers (pen tablets, gamepads, 3D mice)
  clang libclang-rt-14-dev                 # libFuzzer for the HID parser fuzz run
)

missing=()
for p in "${CORE_PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "[install-deps] all ${#CORE_PKGS[@]} packages present" >&2
  exit 0
fi
if [[ $(id -u) -ne 0 ]]; then
  echo "[install-deps] missing packages: ${missing[*]} (run as root, or install them yourself)" >&2
  exit 1
fi
echo "[install-deps] installing: ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}"
