#!/usr/bin/env python3
"""Writes huion_h640p_pen_strokes.hid: a synthetic hid-recorder capture for the Huion H640P pen
descriptor in this folder (report 10: tip/in-range bits, x, y, pressure), made for the tests and
the validation pass, not recorded from a device. The pen touches, bows right and left twice
(x sweeping 0.3 <-> 0.7 of the width, pressure 60 %), lifts, and hovers; 200 reports per second."""
import math, pathlib

here = pathlib.Path(__file__).parent
desc = (here / "huion_h640p_256c_006d_pen.rdesc.bin").read_bytes()
lines = ["D: 0", "R: %d %s" % (len(desc), " ".join("%02x" % b for b in desc)),
         "N: Huion H640P pen (synthetic strokes)", "P: synthetic", "I: 3 256c 006d", "D: 0"]
def report(t, tip, x, y, pressure):
    xi, yi, pi = int(x * 32767), int(y * 32767), int(pressure * 8191)
    b = [10, 0x41 if tip else 0x40, xi & 255, xi >> 8, yi & 255, yi >> 8, pi & 255, pi >> 8, 0, 0]
    lines.append("E: %.6f %d %s" % (t, len(b), " ".join("%02x" % v for v in b)))
t = 0.0
for k in range(100):                       # 0.5 s hovering
    report(t, False, 0.3, 0.5, 0.0); t += 0.005
for k in range(800):                       # 4 s bowing: two strokes each way
    x = 0.5 - 0.2 * math.cos(2 * math.pi * k / 400)
    report(t, True, x, 0.5, 0.6); t += 0.005
for k in range(100):                       # lifted, hovering
    report(t, False, 0.3, 0.5, 0.0); t += 0.005
(here / "huion_h640p_pen_strokes.hid").write_text("\n".join(lines) + "\n")
