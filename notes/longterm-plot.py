#!/usr/bin/env python3
"""Plot of the long-term run for BENCHMARKS.md (issue 12): recognizer seconds per lap along a run
(from a `placewords run --report` JSON, `levels[0].recognize_seconds_by_lap`, mean of 10 laps)
and peak resident memory against laps run.

usage: longterm-plot.py REPORT.json MEMORY.csv OUT.svg
MEMORY.csv: lines `laps,peak_rss_mb` (from `/usr/bin/time -v`, one run per line).
Plain SVG, no plotting library needed.
"""
import json
import math
import sys


def polyline(points, x0, y0, w, h, xmax, ymax, colour):
    pts = " ".join(
        f"{x0 + w * x / xmax:.1f},{y0 + h - h * y / ymax:.1f}" for x, y in points
    )
    return f'<polyline fill="none" stroke="{colour}" stroke-width="1.5" points="{pts}"/>'


def axes(x0, y0, w, h, xmax, ymax, xlabel, ylabel, yfmt):
    out = [f'<rect x="{x0}" y="{y0}" width="{w}" height="{h}" fill="none" stroke="#444"/>']
    for k in range(5):
        y = ymax * k / 4
        py = y0 + h - h * k / 4
        out.append(f'<text x="{x0 - 6}" y="{py + 4:.1f}" text-anchor="end">{yfmt(y)}</text>')
        out.append(f'<line x1="{x0}" x2="{x0 + w}" y1="{py:.1f}" y2="{py:.1f}" stroke="#ddd"/>')
        x = xmax * k / 4
        px = x0 + w * k / 4
        out.append(f'<text x="{px:.1f}" y="{y0 + h + 16}" text-anchor="middle">{x:.0f}</text>')
    out.append(f'<text x="{x0 + w / 2}" y="{y0 + h + 34}" text-anchor="middle">{xlabel}</text>')
    out.append(f'<text x="{x0}" y="{y0 - 8}">{ylabel}</text>')
    return out


def main():
    report, memory, out = sys.argv[1:4]
    secs = json.load(open(report))["levels"][0]["recognize_seconds_by_lap"]
    smooth = [
        (i + 1, sum(secs[max(0, i - 9) : i + 1]) / len(secs[max(0, i - 9) : i + 1]))
        for i in range(len(secs))
    ]
    mem = [tuple(float(v) for v in l.split(",")) for l in open(memory) if l.strip()]
    ms = 1000.0
    # A multiple of 4 ms, so the four grid steps fall on whole milliseconds.
    ymax_t = 4 * math.ceil(max(y for _, y in smooth) * ms * 1.15 / 4)
    ymax_m = max(1024.0, max(m for _, m in mem) * 1.15)
    xmax = max(len(secs), max(l for l, _ in mem))
    parts = [
        '<svg xmlns="http://www.w3.org/2000/svg" width="900" height="340" '
        'font-family="sans-serif" font-size="12">',
        '<rect width="900" height="340" fill="white"/>',
        '<text x="450" y="20" text-anchor="middle" font-size="14">'
        "long-term: 1000 laps of loop-small, 3 levels</text>",
    ]
    parts += axes(70, 50, 340, 230, xmax, ymax_t, "lap", "recognizer thread CPU ms per lap (mean of 10 laps)",
                  lambda v: f"{v:.0f}")
    parts.append(polyline([(x, y * ms) for x, y in smooth], 70, 50, 340, 230, xmax, ymax_t, "#1f77b4"))
    parts += axes(520, 50, 340, 230, xmax, ymax_m, "laps run", "peak resident memory, MB (1 GB line)",
                  lambda v: f"{v:.0f}")
    parts.append(polyline(mem, 520, 50, 340, 230, xmax, ymax_m, "#d62728"))
    for x, y in mem:
        px, py = 520 + 340 * x / xmax, 50 + 230 - 230 * y / ymax_m
        parts.append(f'<circle cx="{px:.1f}" cy="{py:.1f}" r="3" fill="#d62728"/>')
    gy = 50 + 230 - 230 * 1024 / ymax_m
    parts.append(f'<line x1="520" x2="860" y1="{gy:.1f}" y2="{gy:.1f}" stroke="#888" stroke-dasharray="4 3"/>')
    parts.append("</svg>")
    open(out, "w").write("\n".join(parts) + "\n")


if __name__ == "__main__":
    main()
