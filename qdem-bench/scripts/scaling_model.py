#!/usr/bin/env python3
"""A model of the paper-size ballasted track (fixtures/ballast/full_deposit.toml) on N nodes.

Usage:
    python3 qdem-bench/scripts/scaling_model.py [--kernel-core-ms 28.8] [--rest-core-ms 18.5]
        [--particles 293541] [--spheres 279074] [--cores 64] [--bandwidth-gbs 12.5]
        [--latency-us 2] [--bed 3.0,0.6,0.55] [--stone 0.055] [--rebuild-every 1000]
        [--dt 7.30e-8] [--passage 3.67] [--sleepers 1] [--efficiency 1.0] [--nodes 1,8,64]
        [--json FILE]

The inputs are measured on this project's 2-core machine (docs/scaling.md says where each
comes from) except the network, which is stated: one rank per node of CORES cores, nodes
joined by a link of BANDWIDTH GB/s and LATENCY us (100 Gb/s InfiniBand HDR100: 12.5 GB/s,
about 2 us). Per step, on P nodes:

  as built (everything decomposed, the halo exchanged):
      t = (kernel + rest) / (P cores) + halo(P) + rebuild(P)
      halo(P) = 144 B * halo_fraction(P) * particles / bandwidth + 10 * latency  (P > 1)
        per halo particle: its motion out (48 B), its block sums back (24 B) and, as a
        contact ghost, its centre, velocity and spin (72 B); ten collectives a step (the
        block sums, the rebuild decision, the ghosts, the share, the wrap's two, the failure
        check's two, the kinetic energy, the run loop's agreement)
      halo_fraction(P): the settled bed (BED, m) cut into P boxes by halving the longest side,
        each box's shell one stone (STONE, m) thick as a share of the bed's volume
      rebuild(P) = (P - 1) / P * 72 B * spheres / bandwidth / REBUILD_EVERY: at a rebuild of
        the contact lists every rank receives every sphere's record

  before this design (the kernel decomposed, the rest computed whole by every rank, the
  owned particles' motion all-gathered after every step):
      t = kernel / (P cores) + rest / cores + share(P)
      share(P) = (P - 1) / P * 48 B * particles / bandwidth + log2(P) * latency

The core-milliseconds divide over a node's cores at EFFICIENCY (1: perfectly, so the
projections are lower bounds; the measured two-thread speed-up over two gives a stated
figure). SLEEPERS K makes the track K one-sleeper cells long (the paper's Figure 13: 24
sleepers): the work, particles and spheres times K, the bed K times longer along the track
(its second extent). Prints JSON: per P of NODES the step time and the wall time of the 1 s
deposition (1/DT steps: 13.7 M at dt = 7.30e-8 s) and of the PASSAGE s five-car passage
(3.67 s: 50 M steps).
"""

from __future__ import annotations

import argparse
import json
import math

def step_replicated(a, p: int) -> float:
    share = 0.0
    if p > 1:
        share = (p - 1) / p * 48 * a.particles / (a.bandwidth_gbs * 1e9) \
            + math.log2(p) * a.latency_us * 1e-6
    return (a.kernel_core_ms * 1e-3 / (p * a.cores) + a.rest_core_ms * 1e-3 / a.cores) \
        / a.efficiency + share


def halo_fraction(a, p: int) -> float:
    box = list(a.bed)
    parts = 1
    while parts < p:
        i = box.index(max(box))
        box[i] /= 2
        parts *= 2
    inner = box[0] * box[1] * box[2]
    outer = math.prod(min(s + 2 * a.stone, full) for s, full in zip(box, a.bed))
    return (outer - inner) / math.prod(a.bed)


def step_as_built(a, p: int) -> float:
    exchange = 0.0
    if p > 1:
        bandwidth = a.bandwidth_gbs * 1e9
        exchange = 144 * halo_fraction(a, p) * a.particles / bandwidth \
            + 10 * a.latency_us * 1e-6 \
            + (p - 1) / p * 72 * a.spheres / bandwidth / a.rebuild_every
    return (a.kernel_core_ms + a.rest_core_ms) * 1e-3 / (p * a.cores * a.efficiency) + exchange


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--kernel-core-ms", type=float, default=28.8,
                    help="the sleeper and ballast kernels' core-ms per step")
    ap.add_argument("--rest-core-ms", type=float, default=18.5,
                    help="contacts, integration, loads: core-ms per step")
    ap.add_argument("--particles", type=int, default=293_541)
    ap.add_argument("--spheres", type=int, default=279_074)
    ap.add_argument("--rebuild-every", type=float, default=1000.0,
                    help="steps between rebuilds of the contact lists")
    ap.add_argument("--cores", type=int, default=64)
    ap.add_argument("--bandwidth-gbs", type=float, default=12.5)
    ap.add_argument("--latency-us", type=float, default=2.0)
    ap.add_argument("--bed", type=lambda t: [float(v) for v in t.split(",")],
                    default=[3.0, 0.6, 0.55], help="the settled bed's extent x,y,z (m)")
    ap.add_argument("--stone", type=float, default=0.055, help="a stone's size (m)")
    ap.add_argument("--dt", type=float, default=7.30e-8, help="the step (s)")
    ap.add_argument("--passage", type=float, default=3.67, help="the passage's duration (s)")
    ap.add_argument("--sleepers", type=int, default=1, help="one-sleeper cells along the track")
    ap.add_argument("--efficiency", type=float, default=1.0,
                    help="the share of a node's cores' speed the work gets")
    ap.add_argument("--nodes", type=lambda t: [int(v) for v in t.split(",")], default=[1, 8, 64])
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    for key in ("kernel_core_ms", "rest_core_ms", "particles", "spheres"):
        setattr(a, key, getattr(a, key) * a.sleepers)
    a.bed[1] *= a.sleepers
    rows = []
    for p in a.nodes:
        for design, step in (("as built", step_as_built), ("replicated", step_replicated)):
            t = step(a, p)
            rows.append({"nodes": p, "design": design, "step_ms": 1e3 * t,
                         "halo_fraction": halo_fraction(a, p) if design == "as built" else 1.0,
                         "deposition_h": t / a.dt / 3600,
                         "passage_h": t * a.passage / a.dt / 3600})
    out = {"inputs": vars(a), "rows": rows}
    text = json.dumps(out, indent=2)
    print(text)
    if a.json:
        with open(a.json, "w") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    main()
