#!/usr/bin/env python3
"""A place recognizer outside placewords, in Python with the standard library only.

It speaks the plug-in protocol of docs/plugin.md: one JSON object per line on stdin, one
answer per line on stdout. Run it through the harness:

    placewords check scenarios/smoke.toml --recognizer ring=exec:"python3 examples/plugin_recognizer.py"

The method is a deliberately small one, a ring-histogram descriptor: every 0.5 m of odometric
travel it observes the scan as a histogram of its ranges (rotation-invariant, as a ring key is),
and it matches an observation to the most similar earlier one that lies at least 20 m of travel
back, when their histograms agree closely. It is an example of the protocol, not a method to
beat.

Flags for the harness's own tests of failure handling: --crash-at N (exit 3 at frame N),
--hang-at N (stop answering at frame N), --garbage-at N (print a line that is not JSON),
--unknown-frame-at N (name a frame it never observed), --protocol V (answer hello with V).
"""

import json
import math
import sys

SPACING_M = 0.5
MIN_GAP_M = 20.0
BINS = 16
MAX_DISTANCE = 0.08


def flag(name):
    if name in sys.argv:
        return int(sys.argv[sys.argv.index(name) + 1])
    return None


def descriptor(scan):
    """The share of beams in each range bin, up to the scanner's range."""
    max_range = scan["max_range_m"]
    counts = [0] * BINS
    total = 0
    for r in scan["ranges_m"]:
        if r is None or r <= 0.0:
            continue
        b = min(BINS - 1, int(BINS * min(r, max_range) / max_range))
        counts[b] += 1
        total += 1
    return [c / total for c in counts] if total else [0.0] * BINS


def distance(a, b):
    return sum(abs(x - y) for x, y in zip(a, b)) / 2.0


def main():
    crash_at, hang_at = flag("--crash-at"), flag("--hang-at")
    garbage_at, unknown_at = flag("--garbage-at"), flag("--unknown-frame-at")
    protocol = flag("--protocol") or 1
    past = []  # (frame, travel_m, descriptor), oldest first
    travel_m, last_xy, next_at = 0.0, None, 0.0
    for line in sys.stdin:
        msg = json.loads(line)
        kind = msg["type"]
        if kind == "hello":
            answer = {"type": "hello", "protocol": protocol, "name": "ring-histogram"}
        elif kind == "frame":
            frame = msg["frame"]
            if frame == crash_at:
                sys.stderr.write("ring-histogram: crashing on purpose\n")
                sys.exit(3)
            if frame == hang_at:
                while True:
                    pass
            if frame == garbage_at:
                print("this is not JSON", flush=True)
                continue
            odom = msg["odom"]
            xy = (odom["x_m"], odom["y_m"])
            if last_xy is not None:
                travel_m += math.dist(xy, last_xy)
            last_xy = xy
            if travel_m < next_at:
                answer = {"observe": False, "matches": []}
            else:
                next_at = travel_m + SPACING_M
                d = descriptor(msg["scan"])
                best = None
                for f, t, pd in past:
                    if travel_m - t < MIN_GAP_M:
                        continue
                    dist = distance(d, pd)
                    if dist <= MAX_DISTANCE and (best is None or dist < best[1]):
                        best = (f, dist)
                past.append((frame, travel_m, d))
                matches = []
                if unknown_at is not None and frame >= unknown_at:
                    matches.append({"pairs": [[frame, 10**9]]})
                elif best is not None:
                    matches.append(
                        {"pairs": [[frame, best[0]]], "direction": "same", "score": 1.0 - best[1]}
                    )
                answer = {"matches": matches}
        elif kind in ("start_run", "finish"):
            if kind == "start_run":
                last_xy = None
            answer = {"matches": []}
        else:
            answer = {"matches": []}
        print(json.dumps(answer), flush=True)


if __name__ == "__main__":
    main()
