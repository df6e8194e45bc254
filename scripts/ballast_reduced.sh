#!/usr/bin/env bash
# The reduced ballasted track end to end (paper 000 §4; docs/ballast.md):
#   1. the ballast layer and sleeper formed by free fall (reduced_deposit.toml, checkpointed),
#   2. two bogies passing over the settled track (reduced_load.toml, start_from step 1),
#   3. spectra (Parzen, 20 Hz) and mobility of the sensors (qdem analyze),
# and with --friction-study also step 2 and 3 with friction 1.73 (reduced_load_mu173.toml).
# With --stiff, the track at the paper's stiffness ("The track at the paper's stiffness"):
#   1. the layer poured (stiff_deposit.toml) and consolidated by a dynamic track stabiliser's
#      pass (stiff_consolidate.toml),
#   2. the bogies at Table 1's stiffness (stiff_load.toml; stiff_load_mu173.toml beside it
#      with --friction-study),
#   3. the sleeper's modes on its consolidated bed (qdem modes), and the spectra and mobility of
#      the stable period with those modes marked (qdem analyze --modes).
# With --stiff --rigid-forming, step 1 with rigid stones (stiff_deposit_rigid.toml,
# stiff_consolidate_rigid.toml) and step 2 with deformable ones from that bed
# (stiff_load_from_rigid.toml; docs/ballast.md, "Forming rigid, loading deformable").
# With --fine, the reduced layout with 500 stones of the paper's 5 cm size (docs/ballast.md,
# "A bed of 5 cm stones"): the layer poured and consolidated rigid (fine_deposit_rigid.toml,
# fine_consolidate_rigid.toml), then both bogies on it with rigid stones at friction 0.577 and
# 1.73 side by side (fine_load_rigid.toml, fine_load_rigid_mu173.toml).
# With --paper, the same reduced layout with 3,100 of the paper's stones (docs/ballast.md, "The
# reduced track with the paper's stones"): poured and consolidated rigid (paper_deposit_rigid,
# paper_consolidate_rigid), both bogies with rigid stones at friction 0.577 and 1.73 side by
# side (paper_load_rigid, paper_load_rigid_mu173; about 45 min each on one thread alone), and
# the spectra and mobility of the window both carry (0.02-0.15 s) with the paper's peaks and
# the free sleeper's bending modes marked, read by spectrum_peaks.py. The dashpot run
# (paper_load_rigid_dashpot.toml, 1.5 M steps) is run by hand.
# Step 1 is skipped when its checkpoint exists, unless --redeposit is given.
# Outputs: out/ballast/{reduced,stiff}_*/ (probes.csv, vtu/, analysis/*.csv|svg, modes/).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p qdem-cli
qdem=target/release/qdem
dir=fixtures/ballast
redeposit=false
track=reduced
friction=false
rigid=false
fine=false
paper=false
for arg in "$@"; do
    case "$arg" in
        --redeposit) redeposit=true ;;
        --friction-study) friction=true ;;
        --stiff) track=stiff ;;
        --rigid-forming) rigid=true ;;
        --fine) fine=true ;;
        --paper) paper=true ;;
        *) echo "usage: $0 [--stiff [--rigid-forming]] [--fine] [--paper] [--redeposit] [--friction-study]" >&2; exit 2 ;;
    esac
done
forming=(reduced_deposit)
if [ $track = stiff ]; then forming=(stiff_deposit stiff_consolidate); fi
runs=(${track}_load)
if $friction; then runs+=(${track}_load_mu173); fi
if $rigid; then
    if [ $track != stiff ] || $friction; then
        echo "$0: --rigid-forming goes with --stiff, without --friction-study" >&2; exit 2
    fi
    forming=(stiff_deposit_rigid stiff_consolidate_rigid)
    runs=(stiff_load_from_rigid)
fi
if $fine; then
    track=stiff
    forming=(fine_deposit_rigid fine_consolidate_rigid)
    runs=(fine_load_rigid fine_load_rigid_mu173)
fi
if $paper; then
    track=stiff
    forming=(paper_deposit_rigid paper_consolidate_rigid)
    runs=(paper_load_rigid paper_load_rigid_mu173)
fi
if $redeposit || [ ! -f "out/ballast/${forming[-1]}/checkpoint.qdc" ]; then
    for scene in "${forming[@]}"; do $qdem run $dir/$scene.toml; done
fi
if [ $track = reduced ]; then
    for run in "${runs[@]}"; do
        $qdem run $dir/$run.toml
        $qdem analyze $dir/$run.toml --from 0.06
    done
    exit 0
fi
python3 $dir/track_profile.py out/ballast/${forming[-1]} 1045
# The loading runs side by side, one thread each (two cores).
pids=()
for run in "${runs[@]}"; do
    $qdem run $dir/$run.toml --threads $((2 / ${#runs[@]})) &
    pids+=($!)
done
for pid in "${pids[@]}"; do wait "$pid"; done
if $fine; then
    for run in "${runs[@]}"; do python3 $dir/track_profile.py --motion out/ballast/$run; done
    exit 0
fi
if $paper; then
    # Paper 000 §4.2's readings (the rigid vertical mode, the three vertical bending modes,
    # the ballast-sleeper resonance and S2/S3 boundary, the ballast's wheel-load response) and
    # the coarse sleeper's free-free vertical bending modes (sleeper_modes.toml with
    # sleeper_coarse.msh). The bed's own modes are not marked: in the consolidated rigid bed
    # at least 150 stones touch nothing, so its lowest 900 modes are all rigid-body ones.
    marks=(--mark 100=paper:rigid --mark 200=paper:bending-1 --mark 400=paper:bending-2
           --mark 800=paper:bending-3 --mark 320=paper:ballast-sleeper --mark 45=paper:ballast
           --mark 186.1=free-sleeper:bending-1 --mark 523.2=free-sleeper:bending-2
           --mark 984.3=free-sleeper:bending-3)
    for run in "${runs[@]}"; do
        $qdem analyze $dir/$run.toml --from 0.02 --to 0.15 "${marks[@]}"
        python3 $dir/spectrum_peaks.py out/ballast/$run --from 0.02 --to 0.15
        python3 $dir/track_profile.py --motion out/ballast/$run
    done
    exit 0
fi
modes=out/ballast/${runs[0]}/modes
$qdem modes $dir/${runs[0]}.toml --count 80 --out $modes
# Spectra of the stable period: at friction 0.577 the bed fails in bearing under the second
# bogie (from 0.29 s; docs/ballast.md), at 1.73 it carries all four axles.
for run in "${runs[@]}"; do
    window=(--from 0.06)
    if [ "$run" != stiff_load_mu173 ]; then window+=(--to 0.29); fi
    $qdem analyze $dir/$run.toml "${window[@]}" --modes $modes/modes.csv
    python3 $dir/track_profile.py --motion out/ballast/$run
done
