#!/usr/bin/env bash
# Reproduces the figures in notes/recog.md. Usage: notes/recog-measure.sh logs|scenarios [extra recognize args]
# logs: every real log at noise seeds 1-5 (plus Intel --scan-step 2 and 3), 3 levels.
# scenarios [A B C]: each at seeds 1-10 (run --seed), 1, 2 and 3 levels.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-./target/release/placewords}
D=../shared/data/carmen
mode=${1:-logs}; shift || true
summ() { # file -> "precision recall pairs" for levels 3 from the JSON report
  python3 - "$1" <<'PY'
import json,sys
r=json.load(open(sys.argv[1]))
for l in r["levels"]:
    m=l
    d=l.get("directions",{})
    extra=" ".join(f'{k}:R={v.get("recall",0):.3f}' for k,v in d.items())
    print(f'L{l["levels"]} P={m["precision"]:.3f} R={m["recall"]:.3f} pairs={m["pairs"]} {extra}')
PY
}
if [ "$mode" = logs ]; then
  for spec in "intel 1" "intel 2" "intel 3" "fhw 1" "seattle 1" "freiburg-079 1" "csail 1"; do
    set -- $spec; log=$1; k=$2
    for seed in 1 2 3 4 5; do
      out=$(mktemp --suffix .json)
      $BIN recognize $D/$log-corrected.log.gz --quiet --levels 3 --seed $seed --scan-step $k --report $out "${@:3}" >/dev/null 2>&1
      echo "$log step$k seed$seed $(summ $out)"
      rm -f $out
    done
  done
else
  # scenarios [A B C ...]: seeds 1-10 each, all three level configurations
  for scn in ${@:-A B C}; do
    for seed in 1 2 3 4 5 6 7 8 9 10; do
      out=$(mktemp --suffix .json)
      $BIN run scenarios/$scn.toml --quiet --seed $seed --report $out >/dev/null 2>&1 || true
      echo "$scn seed$seed $(summ $out | tr '\n' ' ')"
      rm -f $out
    done
  done
fi
