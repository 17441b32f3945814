#!/usr/bin/env bash
# The Standalone as a musician starts it: JACK (dummy backend: no sound card here) as its audio
# device, a virtual X display, a click held on a key of the window's keyboard, two screenshots
# 0.4 s apart. Passes when every view region shows signal and the views move between shots.
# Usage: standalone-screenshot.sh STANDALONE_BINARY ARTEFACT_DIR
set -euo pipefail
app="$1"
out="$2"
mkdir -p "$out"
work="$(mktemp -d)"
server="rosin-ui-$$"
display=":$((90 + $$ % 100))"
# Stop in order: the Standalone first, so it leaves JACK as a client should; then jackd, waited for,
# so it can release its slot in the machine-wide JACK registry. Stopped all at once, each run leaked
# a slot and its semaphores in /dev/shm, and after about eight runs jackd refused to start.
stop() { [ -n "${1:-}" ] || return 0; kill "$1" 2>/dev/null || true; wait "$1" 2>/dev/null || true; }
cleanup() {
  stop "${app_pid:-}"
  stop "${jack_pid:-}"
  stop "${xvfb_pid:-}"
  # Only a jackd that died on its own leaves these now; they are this run's server's alone.
  rm -f /dev/shm/jack_sem.*_"$server"_* 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

# The Standalone remembers its audio device in ~/.config/Rosin.settings: point it at JACK.
mkdir -p "$work/home/.config"
cat > "$work/home/.config/Rosin.settings" <<'XML'
<?xml version="1.0" encoding="UTF-8"?>
<PROPERTIES>
  <VALUE name="audioSetup">
    <DEVICESETUP deviceType="JACK" audioOutputDeviceName="system" audioInputDeviceName="system"
                 audioDeviceRate="48000.0" audioDeviceBufferSize="256"/>
  </VALUE>
</PROPERTIES>
XML
# JACK_NO_START_SERVER: a client must find our server, never start a default one of its own.
export HOME="$work/home" JACK_DEFAULT_SERVER="$server" DISPLAY="$display" JACK_NO_AUDIO_RESERVATION=1 \
  JACK_NO_START_SERVER=1
Xvfb "$display" -screen 0 1400x900x24 -nolisten tcp >"$work/xvfb.log" 2>&1 &
xvfb_pid=$!
# On a loaded machine jackd has once failed to come up within the old 10 s wait, and the test went
# on without it: wait for it by asking it for its ports, start it again if it died, and stop with
# its log when it never answers, so a missing server is never mistaken for a Standalone fault.
jack_up=0
for attempt in 1 2 3; do
  jackd --no-realtime -n "$server" -d dummy -r 48000 -p 256 >"$work/jack-$attempt.log" 2>&1 &
  jack_pid=$!
  for _ in $(seq 100); do
    if jack_lsp >/dev/null 2>&1; then jack_up=1; break; fi
    kill -0 "$jack_pid" 2>/dev/null || break
    sleep 0.2
  done
  [ "$jack_up" -eq 1 ] && break
  echo "jackd (attempt $attempt) did not answer:"; cat "$work/jack-$attempt.log"
  stop "$jack_pid"
done
[ "$jack_up" -eq 1 ] || { echo "FAIL: no JACK server to test the Standalone on"; exit 1; }
for _ in $(seq 100); do xdpyinfo >/dev/null 2>&1 && break; sleep 0.2; done
xdpyinfo >/dev/null 2>&1 || { echo "FAIL: no X display"; cat "$work/xvfb.log"; exit 1; }
"$app" >"$work/app.log" 2>&1 &
app_pid=$!
win="$(timeout 20 xdotool search --sync --name '^Rosin$' | head -1)"
sleep 2
# The Standalone opens its device a moment after its window appears: give it up to 10 s.
for _ in $(seq 50); do jack_lsp | grep -q "Rosin:out_1" && break; sleep 0.2; done
jack_lsp | grep -q "Rosin:out_1" || { echo "FAIL: the Standalone did not open JACK"; cat "$work/app.log" "$work"/jack-*.log; exit 1; }
eval "$(xdotool getwindowgeometry --shell "$win")" # X Y WIDTH HEIGHT
import -window root "$out/standalone-before.png"
# Hold a key in the middle of the keyboard strip along the bottom of the window.
xdotool mousemove --window "$win" $((WIDTH * 42 / 100)) $((HEIGHT - 35)) mousedown 1
sleep 3
import -window root "$out/standalone-playing.png"
sleep 0.4
import -window root "$out/standalone-playing-later.png"
xdotool mouseup 1

# The four views fill the right part of the window between the top bar and the keyboard.
vx=$((X + WIDTH * 36 / 100)); vw=$((WIDTH * 62 / 100)); vy=$((Y + HEIGHT * 12 / 100)); vh=$((HEIGHT * 70 / 100))
fail=0
for q in 0 1 2 3; do
  qx=$((vx + (q % 2) * vw / 2 + vw / 12)); qy=$((vy + (q / 2) * vh / 2 + vh / 12))
  crop="$((vw / 3))x$((vh / 3))+$qx+$qy"
  colours=$(convert "$out/standalone-playing.png" -crop "$crop" +repage -format "%k" info:)
  before=$(convert "$out/standalone-before.png" -crop "$crop" +repage -format "%k" info:)
  echo "view $q: $colours colours while playing ($before before)"
  if [ "$q" -eq 3 ]; then
    # The Schelleng map is drawn before any note (for the selected string), so its colour count
    # says nothing: while playing it must be redrawn for the note, with the player's marker.
    changed=$(compare -metric AE -fuzz 5% "$out/standalone-before.png" "$out/standalone-playing.png" -crop "$crop" null: 2>&1 || true)
    echo "view 3: $changed pixels differ from before"
    if [ "$colours" -lt 40 ] || [ "${changed%%.*}" -lt 500 ]; then echo "FAIL: view 3 does not follow the note"; fail=1; fi
  elif [ "$colours" -lt 40 ] || [ "$colours" -le "$before" ]; then echo "FAIL: view $q shows no signal"; fail=1; fi
done
moved=$(compare -metric AE -crop "${vw}x${vh}+${vx}+${vy}" "$out/standalone-playing.png" "$out/standalone-playing-later.png" null: 2>&1 || true)
echo "pixels changed in the views in 0.4 s: $moved"
if [ "${moved%%.*}" -lt 500 ]; then echo "FAIL: the views do not move"; fail=1; fi
exit $fail
