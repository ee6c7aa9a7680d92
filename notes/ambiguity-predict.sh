#!/usr/bin/env bash
# Issue 26 point 1: does the ambiguity map predict the recognizer's false pairs?
# Runs `world ambiguity --scenario … --measure SEEDS` on the shipped A, B, C and on ten
# generated floors with a door-change scenario each (written into $OUT), and prints one JSON
# line per scenario. Usage: notes/ambiguity-predict.sh [OUT_DIR] [SEEDS]   (default /tmp/ambiguity, 1..3)
# About 2 CPU minutes for A, B and C at 3 seeds, and one for the ten generated floors.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/ambiguity}
seeds=${2:-1..3}
bin=${PLACEWORDS:-target/release/placewords}
mkdir -p "$out"
for k in $(seq 1 10); do
  # Odd seeds: single-loaded 40 x 30 m floors; even: double-loaded 60 x 30 m wards; every
  # third: corridors that look alike on purpose.
  args=(--seed "$k")
  if (( k % 2 == 0 )); then args+=(--size-m 60,30 --double-loaded --rooms 30); else args+=(--rooms 14); fi
  if (( k % 3 == 0 )); then args+=(--look-alike); fi
  "$bin" world generate "${args[@]}" -o "$out/g$k.toml" 2>/dev/null
  python3 - "$out/g$k.toml" "$out/g$k.scenario.toml" "$k" <<'PY'
import sys, tomllib, random
world, scenario, k = sys.argv[1], sys.argv[2], int(sys.argv[3])
doors = [d["id"] for d in tomllib.load(open(world, "rb")).get("doors", [])]
rng = random.Random(k)
a = sorted(rng.sample(doors, max(1, len(doors) // 4)))
b = sorted(rng.sample(doors, max(1, len(doors) // 4)))
q = lambda ids: "[" + ", ".join(f'"{i}"' for i in ids) + "]"
open(scenario, "w").write(f'''format_version = 1
name = "generated-{k}"
world = "g{k}.toml"
route = "lap"
seed = {k}

[door_configs]
a = {q(a)}
b = {q(b)}

[[runs]]
start_waypoint = 0
laps = 4
doors_cycle = ["all-closed", "a", "all-closed", "b"]

[[runs]]
start_waypoint = 1
laps = 4
doors_cycle = ["a", "all-closed", "b", "all-closed"]

[robot]
lane_offset_ratio = 0.8
lap_speed_spread_ratio = 0.2
speed_wave_ratio = 0.25

[laser]
preset = "lms200"

[odometry]
model = "proportional"
''')
PY
done
# SHIPPED="" leaves A, B and C out (to run the generated floors only).
for s in ${SHIPPED-scenarios/A.toml scenarios/B.toml scenarios/C.toml} "$out"/g*.scenario.toml; do
  name=$(basename "$s" .toml)
  "$bin" world ambiguity --scenario "$s" -o "$out/$name.svg" --measure "$seeds" --json \
    > "$out/$name.json" 2> "$out/$name.err" || { echo "{\"scenario\": \"$name\", \"error\": true}"; continue; }
  python3 -c "
import json,sys
d=json.load(open(sys.argv[1])); p=d['prediction']
print(json.dumps({'scenario': p['scenario'], 'route_m': round(d['route_length_m']), 'door_sets': len(d['door_sets']),
  'false_pairs': p['false_pairs'], 'pairs': p['pairs'], 'predicted_share': round(p['predicted_share'],3),
  'flagged_share': round(p['flagged_share'],3), 'lift': round(p['lift'],2), 'slip_pairs': p['slip_pairs'],
  'look_alike': p['predicted_look_alike'], 'door_change': p['predicted_door_change'], 'slip': p['predicted_slip'],
  'per_seed': p['per_seed']}))" "$out/$name.json"
done
