#!/usr/bin/env bash
# The test command of README.md: installs the Python client the tests read our output with
# (meshio), then runs every test of the workspace. Works on a fresh machine with cargo and
# python3.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! python3 -c "import meshio" 2>/dev/null; then
    python3 -m pip install --quiet --disable-pip-version-check meshio
fi
# Only the seam calls a collective (docs/architecture.md, "The ranks, behind one seam"): the
# decomposition lives in qdem-core/src/parallel/, the World offers its collectives as named
# methods (World::gather, World::agree_on_stop, World::rank_rows, ...), World::decompose takes
# the Communicator, and the CLI's MPI set-up makes it and hands it over. Outside the seam no
# file names the Communicator, one of its collectives (its `min`, `rank` and `size` are
# reached only through a value of it, so only by naming it) or the parallel runtime's raw
# ones: a model or a driver that did would be calling collectives itself.
seam='^(qdem-core/src/parallel/|qdem-core/src/lib\.rs|qdem-core/src/world\.rs|qdem-cli/src/(main|mpi_ranks|command|check)\.rs)'
collectives='Communicator|all_to_all|all_gather|all_gather_one|all_gather_varying|broadcast|agree_min|gather_values|max_over_ranks'
outside=$(grep -rnwE --include='*.rs' "$collectives" qdem-* | grep -Ev "$seam" || true)
if [ -n "$outside" ]; then
    echo "these lines name a collective outside the seam (qdem-core/src/parallel/ and the World);" >&2
    echo "call a named World method instead (World::gather, World::agree_on_stop, ...):" >&2
    echo "$outside" >&2
    exit 1
fi
# One build from scratch: incremental caches would only double the target folder's size.
export CARGO_INCREMENTAL="${CARGO_INCREMENTAL:-0}"
# The embedding examples (qdem-core's beam_under_load, qdem-contact's two_bodies_collide and
# spheres_on_wall) run among these targets (`test = true, harness = false` in their crates'
# Cargo.toml): each checks a physical quantity and exits non-zero when it is off. Run alone,
# `cargo run -p CRATE --example` would build the dependencies again for that crate's features.
cargo test --workspace --all-targets
cargo test --workspace --doc
# The MPI runs (`mpirun -np N qdem run`, byte-identical for 1-3 ranks): Open MPI and, for
# rsmpi's bindgen, libclang, installed from Debian's packages where missing.
if ! dpkg -s openmpi-bin libopenmpi-dev libclang-dev >/dev/null 2>&1; then
    SUDO=""
    if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq openmpi-bin libopenmpi-dev libclang-dev >/dev/null
fi
cargo test -p qdem-cli --features mpi --test mpi_runs
