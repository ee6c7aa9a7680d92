#!/usr/bin/env python3
"""Table I rows (mean / worst (seed) over seeds) from a `placewords run --seeds` report."""
import json, sys

LABEL = {"words-1": "words, 1 level", "words-2": "words, 2 levels", "words-3": "words, 3 levels",
         "scan-context": "Scan Context", "icp": "ICP"}

def reports(j):
    if "scenarios" in j:
        for sc in j["scenarios"]:
            for r in sc["results"]:
                if r.get("report"):
                    yield r["seed"], r["report"]
    else:
        yield j["seed"], j

def subjects(rep):
    return rep.get("subjects") or rep.get("levels")

def cell(vals, skip_no_pairs=False):
    v = [(s, x) for s, x, no in vals if not (skip_no_pairs and no)]
    if not v:
        return "no pairs"
    mean = sum(x for _, x in v) / len(v)
    seed, worst = min(v, key=lambda t: (t[1], t[0]))
    out = f"{mean:.3f} / {worst:.3f} (s{seed})"
    n_no = len(vals) - len(v)
    return out + (f"; {n_no} seed(s) no pairs" if n_no else "")

j = json.load(open(sys.argv[1]))
label = sys.argv[2] if len(sys.argv) > 2 else None
data = {}
for seed, rep in reports(j):
    for s in subjects(rep):
        data.setdefault(s["name"], []).append((seed, s))
ORDER = list(LABEL)
for name, per in sorted(data.items(), key=lambda kv: (ORDER.index(kv[0]) if kv[0] in ORDER else 99, kv[0])):
    g = lambda k: [(seed, s[k], s.get("no_pairs", False)) for seed, s in per]
    secs = sum(s["recognize_seconds_per_lap"] for _, s in per) / len(per)
    print(f"| {label or j.get('scenario', '?')} | {LABEL.get(name, name)} | {cell(g('precision'), True)} | "
          f"{cell(g('recall'))} | {cell(g('visit_recall'))} | {secs:.2f} |")
print("seeds:", sorted({seed for seed, _ in reports(j)}), file=sys.stderr)
