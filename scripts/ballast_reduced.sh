#!/usr/bin/env bash
# The reduced ballasted track end to end (paper 000 §4; docs/ballast.md):
#   1. the ballast layer and sleeper formed by free fall (reduced_deposit.toml, checkpointed),
#   2. two bogies passing over the settled track (reduced_load.toml, start_from step 1),
#   3. spectra (Parzen, 20 Hz) and mobility of the sensors (qdem analyze),
# and with --friction-study also step 2 and 3 with friction 1.73 (reduced_load_mu173.toml).
# Step 1 is skipped when its checkpoint exists, unless --redeposit is given.
# Outputs: out/ballast/reduced_{deposit,load,load_mu173}/ (probes.csv, vtu/, analysis/*.csv|svg).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p qdem-cli
qdem=target/release/qdem
dir=fixtures/ballast
redeposit=false
runs=(reduced_load)
for arg in "$@"; do
    case "$arg" in
        --redeposit) redeposit=true ;;
        --friction-study) runs+=(reduced_load_mu173) ;;
        *) echo "usage: $0 [--redeposit] [--friction-study]" >&2; exit 2 ;;
    esac
done
if $redeposit || [ ! -f out/ballast/reduced_deposit/checkpoint.qdc ]; then
    $qdem run $dir/reduced_deposit.toml
fi
for run in "${runs[@]}"; do
    $qdem run $dir/$run.toml
    $qdem analyze $dir/$run.toml --from 0.06
done
