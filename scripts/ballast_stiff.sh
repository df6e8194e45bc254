#!/usr/bin/env bash
# The reduced ballasted track at the paper's stiffness end to end (paper 000 §4; docs/ballast.md,
# "The track at the paper's stiffness"):
#   1. the ballast layer and sleeper formed by free fall (stiff_deposit.toml),
#   2. consolidated by a dynamic track stabiliser's pass (stiff_consolidate.toml),
#   3. two bogies passing over the consolidated track at E 30/45 GPa, springs 1.613/0.672 GN/m
#      (stiff_load.toml; with --friction-study also stiff_load_mu173.toml, beside it),
#   4. the sleeper's modes on its consolidated bed (qdem modes), and the sensors' spectra and
#      mobility of the stable period with those modes marked (qdem analyze --modes).
# Steps 1 and 2 are skipped when the consolidated checkpoint exists, unless --redeposit is given.
# Outputs: out/ballast/stiff_{deposit,consolidate,load,load_mu173}/.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p qdem-cli
qdem=target/release/qdem
dir=fixtures/ballast
redeposit=false
runs=(stiff_load)
for arg in "$@"; do
    case "$arg" in
        --redeposit) redeposit=true ;;
        --friction-study) runs+=(stiff_load_mu173) ;;
        *) echo "usage: $0 [--redeposit] [--friction-study]" >&2; exit 2 ;;
    esac
done
if $redeposit || [ ! -f out/ballast/stiff_consolidate/checkpoint.qdc ]; then
    $qdem run $dir/stiff_deposit.toml
    $qdem run $dir/stiff_consolidate.toml
fi
python3 $dir/track_profile.py out/ballast/stiff_consolidate 1045
# The loading runs side by side, one thread each (two cores).
pids=()
for run in "${runs[@]}"; do
    $qdem run $dir/$run.toml --threads $((2 / ${#runs[@]})) &
    pids+=($!)
done
for pid in "${pids[@]}"; do wait "$pid"; done
modes=out/ballast/stiff_load/modes
$qdem modes $dir/stiff_load.toml --count 80 --out $modes
# Spectra of the stable period: at friction 0.577 the bed fails in bearing under the second
# bogie (from 0.29 s; docs/ballast.md), at 1.73 it carries all four axles.
for run in "${runs[@]}"; do
    window=(--from 0.06)
    if [ "$run" = stiff_load ]; then window+=(--to 0.29); fi
    $qdem analyze $dir/$run.toml "${window[@]}" --modes $modes/modes.csv
    python3 $dir/track_profile.py --motion out/ballast/$run
done
