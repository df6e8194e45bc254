#!/usr/bin/env python3
"""Where the time of a poured, periodic bed run through `qdem run` goes beyond the lattice
benchmark, in instructions (callgrind: independent of the machine's load), per function.

Usage (from the workspace root; valgrind installed; the binaries of one build):

    python3 qdem-bench/scripts/poured_profile.py [--spheres 2000] [--steps 20,70]
        [--qdem target/release/qdem] [--study target/release/study] [--work out/poured_profile]
        [--orders [--ll 262144,8,64]]

Two beds of the same sphere count and material (r = 5 mm, E = 50 MPa, Hertz-Mindlin with
friction and restitution 0.5, skin 1 mm, the common step 20% of the Rayleigh time):
- poured: poured_compare.py's insertion poured by `qdem run` in a cell periodic in x and y on
  a floor, then run from its checkpoint by `qdem run` (the run's own per-step work included:
  the periodic wrap and images, the contact watch, the recorders' schedules);
- lattice: `study packing --spheres N --settle 0.2` (a lattice poured into a box of a floor
  and four walls) timed by `study dem-throughput` (the engine's step loop alone).
Each is run under `valgrind --tool=callgrind` for the two step counts on one thread; the
difference of the two runs, over spheres x the steps between them, takes the set-up out and
gives instructions per sphere-step, per function (exclusive, `callgrind_annotate`). With
`--orders`, the poured bed's settled positions in lattice, poured and random order
(poured_compare.py's `order` part) are run from rest under `valgrind --tool=cachegrind` with a
last-level cache of `--ll` (smaller than the machine's, so that a small bed leaves it as a large
one leaves the real one): instructions and misses per sphere-step, load-independent. Writes
WORK/poured_profile.json and a markdown table (stdout and WORK/poured_profile.md).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import poured_compare as pcmp  # noqa: E402

ROOT = pcmp.ROOT
LINE_RE = re.compile(r"^\s*([\d,]+)\s+(?:\(\s*[\d.]+%\)\s+)?(\S.*)$")


def log(msg: str) -> None:
    print(f"[poured_profile] {msg}", file=sys.stderr, flush=True)


def callgrind(cmd: list[str], cwd: Path, out: Path) -> tuple[dict[str, int], dict[str, int]]:
    """Runs cmd under callgrind on one thread (unless `out` is there from an earlier run);
    returns the exclusive Ir per function and per source file (the file an instruction's line
    is in: code inlined from another file counts there)."""
    if not out.exists():
        env = dict(os.environ, RAYON_NUM_THREADS="1")
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", *cmd],
                       cwd=cwd, check=True, env=env, capture_output=True)
    text = subprocess.run(["callgrind_annotate", "--threshold=100", "--inclusive=no",
                           "--auto=no", str(out)],
                          check=True, capture_output=True, text=True).stdout
    functions: dict[str, int] = {}
    files: dict[str, int] = {}
    started = False
    for line in text.splitlines():
        if "file:function" in line:
            started = True
            continue
        if not started or line.startswith("---"):
            continue
        if not line.strip():
            if functions:
                break
            continue
        m = LINE_RE.match(line)
        if m:
            where = re.sub(r"\s+\[[^\]]*\]$", "", m.group(2))
            path, _, name = where.partition(":")
            cost = int(m.group(1).replace(",", ""))
            functions[name] = functions.get(name, 0) + cost
            files[source(path)] = files.get(source(path), 0) + cost
    return functions, files


def cachegrind(cmd: list[str], cwd: Path, out: Path, ll: str) -> dict[str, int]:
    """Runs cmd under cachegrind (one thread, a last-level cache of `ll`, unless `out` is there
    from an earlier run); returns the program's totals: Ir, D1 misses (D1mr + D1mw) and
    last-level misses (DLmr + DLmw)."""
    if not out.exists():
        env = dict(os.environ, RAYON_NUM_THREADS="1")
        subprocess.run(["valgrind", "--tool=cachegrind", "--cache-sim=yes", f"--LL={ll}",
                        f"--cachegrind-out-file={out}", *cmd], cwd=cwd, check=True, env=env,
                       capture_output=True)
    events, totals = [], []
    for line in out.read_text().splitlines():
        if line.startswith("events:"):
            events = line.split()[1:]
        elif line.startswith("summary:"):
            totals = [int(v) for v in line.split()[1:]]
    t = dict(zip(events, totals))
    return {"Ir": t["Ir"], "D1 misses": t["D1mr"] + t["D1mw"], "LL misses": t["DLmr"] + t["DLmw"]}


def orders_study(qdem: Path, d: Path, side: float, n: int, s0: int, s1: int, work: Path,
                 ll: str) -> list[str]:
    """The settled bed's positions in lattice, poured and random order (poured_compare.py's
    `order` part), each run by `qdem run` from rest under cachegrind: per sphere-step, the
    instructions and the misses, which the order changes and the load does not."""
    settled = pcmp.read_stones(d / "qdem_pour" / "stones.csv")
    rows = ["| order | instructions | D1 misses | misses past a "
            f"{int(ll.split(',')[0]) // 1024} KiB cache |", "| --- | --- | --- | --- |"]
    for name, rs in pcmp.orders(settled, side).items():
        pcmp.write_stones(d / f"order_{name}.csv", [(r[1], r[2], r[3]) for r in rs])
        runs = {}
        for s in (s0, s1):
            scene = d / f"order_{name}_{s}.toml"
            scene.write_text(pcmp.qdem_scene(side, pcmp.common_dt(), s * pcmp.common_dt(),
                                             f"order_{name}_{s}", sample=f"order_{name}.csv"))
            log(f"cachegrind: qdem run, {name} order, {s} steps")
            runs[s] = cachegrind([str(qdem), "run", scene.name, "--threads", "1", "--yes"], d,
                                 work / f"cachegrind.{name}.{s}", ll)
        per = {k: (runs[s1][k] - runs[s0][k]) / (n * (s1 - s0)) for k in runs[s0]}
        rows.append(f"| {name} | {per['Ir']:,.1f} | {per['D1 misses']:,.2f} | "
                    f"{per['LL misses']:,.2f} |")
    return rows


def source(path: str) -> str:
    """A source file's path from its crate (qdem-contact/src/...) or its library."""
    for marker in ("/work/", "/library/", "/src/"):
        if marker in path:
            tail = path.split(marker, 1)[1]
            return tail.split("/", 1)[1] if marker == "/work/" else tail
    return path


def per_step(short: dict, long: dict, sphere_steps: int) -> dict[str, float]:
    return {k: (long.get(k, 0) - short.get(k, 0)) / sphere_steps for k in set(short) | set(long)}


def short_name(name: str, width: int = 90) -> str:
    name = re.sub(r"::h[0-9a-f]{16}$", "", name)
    return name if len(name) <= width else "…" + name[-width:]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spheres", type=int, default=2000)
    ap.add_argument("--steps", default="20,70")
    ap.add_argument("--qdem", default=str(ROOT / "target" / "release" / "qdem"))
    ap.add_argument("--study", default=str(ROOT / "target" / "release" / "study"))
    ap.add_argument("--work", default="out/poured_profile")
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--orders", action="store_true",
                    help="also the bed in lattice, poured and random order under cachegrind")
    ap.add_argument("--ll", default="262144,8,64",
                    help="cachegrind's last-level cache for --orders (size,assoc,line)")
    args = ap.parse_args()
    s0, s1 = (int(s) for s in args.steps.split(","))
    n = args.spheres
    work = Path(args.work) if Path(args.work).is_absolute() else ROOT / args.work
    work.mkdir(parents=True, exist_ok=True)
    qdem, study = work / "qdem", work / "study"
    shutil.copy2(args.qdem, qdem)
    shutil.copy2(args.study, study)

    # the poured bed, poured once without valgrind
    d = work / f"poured_n{n}"
    d.mkdir(exist_ok=True)
    side, pts = pcmp.cached_insertion(n, d)
    if not (d / "qdem_pour" / "checkpoint.qdc").exists():
        pcmp.qdem_pour(qdem, d, side, pts, 0.25, 2)
    poured = {}
    for s in (s0, s1):
        scene = d / f"profile_{s}.toml"
        scene.write_text(pcmp.qdem_scene(side, pcmp.common_dt(), s * pcmp.common_dt(),
                                         f"profile_{s}", sample="insert.csv",
                                         start_from="qdem_pour/checkpoint.qdc"))
        log(f"callgrind: qdem run, poured bed, {s} steps")
        poured[s] = callgrind([str(qdem), "run", scene.name, "--threads", "1", "--yes"], d,
                              work / f"callgrind.poured.{s}")
        steps = json.loads((d / f"profile_{s}" / "summary.json").read_text())["steps"]
        if steps != s:
            sys.exit(f"error: the poured run took {steps} steps, not {s}")

    # the lattice bed of the same size
    lat = work / f"lattice_n{n}"
    if not (lat / "packing.json").exists():
        subprocess.run([str(study), "packing", "--spheres", str(n), "--out", str(lat),
                        "--settle", "0.2"], check=True, cwd=ROOT)
    lattice = {}
    for s in (s0, s1):
        log(f"callgrind: study dem-throughput, lattice bed, {s} steps")
        lattice[s] = callgrind([str(study), "dem-throughput", "--packing", str(lat), "--steps",
                                str(s)], ROOT, work / f"callgrind.lattice.{s}")

    # candidates (pairs and wall contacts in the lists) per sphere, to compare per candidate
    check = subprocess.run([str(qdem), "check", f"profile_{s0}.toml", "--threads", "1"], cwd=d,
                           capture_output=True, text=True).stdout
    m = re.search(r"(\d+) candidate pairs and wall contacts", check)
    cand_p = int(m.group(1)) / n if m else None
    out = subprocess.run([str(study), "dem-throughput", "--packing", str(lat), "--steps", "1"],
                         cwd=ROOT, capture_output=True, text=True,
                         env=dict(os.environ, RAYON_NUM_THREADS="1")).stdout
    cand_q = json.loads([line for line in out.splitlines() if line.startswith("{")][-1])[
        "candidates_per_sphere"]
    sphere_steps = n * (s1 - s0)
    lines = [f"Instructions per sphere-step ({n:,} spheres, steps {s0} to {s1}, one thread; "
             "callgrind, exclusive), by function and by the source file of each instruction "
             "(code inlined from another file counts there):", ""]
    doc = {"spheres": n, "steps": [s0, s1], "candidates_per_sphere": {"poured": cand_p,
                                                                        "lattice": cand_q}}
    if cand_p:
        lines += [f"Candidates per sphere (pairs and wall contacts in the lists): poured "
                  f"{cand_p:.2f} (`qdem check`, at the start), lattice {cand_q:.2f} "
                  "(`dem-throughput`).", ""]
    for view, k in (("function", 0), ("source file", 1)):
        p = per_step(poured[s0][k], poured[s1][k], sphere_steps)
        q = per_step(lattice[s0][k], lattice[s1][k], sphere_steps)
        names = sorted(set(p) | set(q), key=lambda x: -max(abs(p.get(x, 0)), abs(q.get(x, 0))))
        total_p, total_q = sum(p.values()), sum(q.values())
        lines += [f"| {view} | poured, periodic (`qdem run`) | lattice (`dem-throughput`) | "
                  "poured − lattice |", "| --- | --- | --- | --- |",
                  f"| **all** | **{total_p:,.0f}** | **{total_q:,.0f}** | "
                  f"**{total_p - total_q:+,.0f}** |"]
        for name in names[:args.top]:
            a, b = p.get(name, 0.0), q.get(name, 0.0)
            lines.append(f"| `{short_name(name)}` | {a:,.1f} | {b:,.1f} | {a - b:+,.1f} |")
        lines.append("")
        doc[view] = {"poured_total": total_p, "lattice_total": total_q,
                     "poured": dict(sorted(p.items(), key=lambda t: -abs(t[1]))),
                     "lattice": dict(sorted(q.items(), key=lambda t: -abs(t[1])))}
    if args.orders:
        lines += [f"The same settled positions in three orders (`qdem run` from rest, one "
                  f"thread, cachegrind, per sphere-step from steps {s0} to {s1}):", ""]
        lines += orders_study(qdem, d, side, n, s0, s1, work, args.ll)
        lines.append("")
    table = "\n".join(lines) + "\n"
    (work / "poured_profile.md").write_text(table)
    (work / "poured_profile.json").write_text(json.dumps(doc, indent=2) + "\n")
    print(table)


if __name__ == "__main__":
    main()
