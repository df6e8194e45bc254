#!/usr/bin/env bash
# The averaged-pressure tetrahedron's cost on the wall clock, for a quiet machine
# (docs/verification.md, averaged pressure, "Cost"): `qdem bench` of the standard and the
# averaged-pressure tetrahedron at 10^5 and 10^6 tets on 1 and 2 threads (elastic and
# viscoelastic), for this tree's binary and a previous one, alternated, ROUNDS rounds; prints
# per row the standard ÷ averaged tet-steps/s of each binary (the issue's target: ≤ 1.3).
#
#   scripts/averaged_pressure_wall_clock.sh PREVIOUS_QDEM [ROUNDS=2] [OUT=target/avgp-wall]
#
# Builds target/release/qdem first (cargo build --release -p qdem-cli).
set -euo pipefail
previous=${1:?usage: $0 PREVIOUS_QDEM [ROUNDS] [OUT]}
rounds=${2:-2}
out=${3:-target/avgp-wall}
cargo build --release -p qdem-cli
mkdir -p "$out"
for round in $(seq 1 "$rounds"); do
    for binary in "$previous" target/release/qdem; do
        name=$([ "$binary" = "$previous" ] && echo previous || echo this)
        for formulation in standard averaged-pressure; do
            "$binary" bench --json --tets 100000,1000000 --threads 1,2 \
                --formulation "$formulation" > "$out/$round-$name-$formulation.json"
        done
    done
done
python3 - "$out" "$rounds" <<'PY'
import json, sys
out, rounds = sys.argv[1], int(sys.argv[2])
def rows(path):
    doc = json.load(open(path))
    return {(r["tets"], r["material"], r["threads"]): r["tet_steps_per_second"] for r in doc["results"]}
print(f"{'round':>5} {'binary':>8} {'tets':>8} {'material':>12} {'threads':>7} {'standard':>11} {'averaged':>11} {'ratio':>6}")
for round in range(1, rounds + 1):
    for name in ("previous", "this"):
        s = rows(f"{out}/{round}-{name}-standard.json")
        a = rows(f"{out}/{round}-{name}-averaged-pressure.json")
        for key in sorted(s):
            if key in a:
                print(f"{round:>5} {name:>8} {key[0]:>8} {key[1]:>12} {key[2]:>7} {s[key]:>11.4e} {a[key]:>11.4e} {s[key] / a[key]:>6.2f}")
PY
