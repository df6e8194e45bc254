#!/usr/bin/env python3
"""The oedometer of a LIGGGHTS user, in qdem and in LIGGGHTS 3.8 at the user's step (issue 57,
"an oedometer of 3,000 spheres ... accepted at dt = 2e-5 s, where LIGGGHTS runs it stably").

Usage (from the workspace root, after `cargo build --release -p qdem-cli --bin qdem`):

    python3 qdem-bench/scripts/oedometer_compare.py [--spheres 3000] [--dt 2e-5]
        [--seconds 2.0] [--work out/oedometer_peers] [--qdem target/release/qdem]
        [--threads 2]

The test is stage 1 of fixtures/oedometer/ (load.toml: grains poured into a square box with
frictionless sides, a floor with friction, a servo lid driven to 20 kPa from the start) with the
user's grains: `--spheres` spheres of d = 8-12 mm (uniform in d by number), E = 50 MPa,
nu = 0.25, rho = 2500 kg/m3, mu = 0.5, restitution 0.5, Hertz-Mindlin, in a box whose side
makes the settled bed about as high as it is wide. The script draws the insertion once (random
sequential addition, seeded, 2.1 radii apart, to a volume fraction of 0.2, in the order drawn)
and both codes pour it at rest under the lid, which starts above the insertion and approaches at
up to 0.2 m/s: qdem with the fixture's `servo = { stress, area, max_velocity }` (PFC's gain),
LIGGGHTS with `fix mesh/surface/stress/servo` on a two-triangle STL lid a diameter wider than
the box (proportional, kp = 1: v = v_max (F - F_target) / F_target).

Checked and compared at the end, from each code's own output with the same estimators:
- stable: the kinetic energy bounded (its largest value after the lid first touches, against
  the pour's potential energy) and no sphere lost (every sphere inside the box);
- the end state: porosity 1 - V_spheres / (A h) with h the lid's height; coordination
  2 * (overlapping sphere pairs) / N from the final positions (the same pair count for both
  codes); the lid's force against its target (stress x area).
The rows go to WORK/oedometer_compare.json and a markdown table to stdout.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import shutil
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import liggghts_compare as lc  # noqa: E402
import poured_compare as pcmp  # noqa: E402

ROOT = lc.ROOT
HERE = Path(__file__).resolve().parent
D_MIN, D_MAX = 0.008, 0.012
DENSITY = 2500.0
YOUNG = 5.0e7
POISSON = 0.25
FRICTION = 0.5
RESTITUTION = 0.5
STRESS = 20e3
VMAX = 0.2
BED_FRACTION = 0.6
INSERT_FRACTION = 0.2


def log(msg: str) -> None:
    print(f"[oedometer_compare] {msg}", file=sys.stderr, flush=True)


fmt = pcmp.fmt


def insertion(n: int, seed: int = 57):
    """Radii uniform in d over [D_MIN, D_MAX]; centres by random sequential addition in the box
    (walls at 0 and side), above the floor, to INSERT_FRACTION; in the order drawn."""
    rng = random.Random(seed)
    radii = [0.5 * (D_MIN + (D_MAX - D_MIN) * rng.random()) for _ in range(n)]
    vol = sum(4.0 / 3.0 * math.pi * r ** 3 for r in radii)
    side = (vol / BED_FRACTION) ** (1.0 / 3.0)
    height = vol / (INSERT_FRACTION * side * side)
    h = 1.05 * D_MAX
    grid: dict[tuple[int, int, int], list[int]] = {}
    pts: list[tuple[float, float, float, float]] = []
    for r in radii:
        for _ in range(100000):
            p = (r * 1.05 + rng.random() * (side - 2.1 * r), r * 1.05 + rng.random() * (side - 2.1 * r),
                 r * 1.05 + rng.random() * height)
            c = tuple(int(v / h) for v in p)
            ok = all((p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2
                     >= (1.05 * (r + q[3])) ** 2
                     for di in (-1, 0, 1) for dj in (-1, 0, 1) for dk in (-1, 0, 1)
                     for q in (pts[k] for k in grid.get((c[0] + di, c[1] + dj, c[2] + dk), ())))
            if ok:
                grid.setdefault(c, []).append(len(pts))
                pts.append((*p, r))
                break
        else:
            sys.exit(f"error: random insertion stalled at {len(pts)} of {n} spheres")
    return side, pts


def lid_start(pts) -> float:
    return max(p[2] + p[3] for p in pts) + D_MAX


def coordination(spheres) -> tuple[float, int]:
    """2 * overlapping pairs / N, and the pairs, from (x, y, z, r)."""
    h = D_MAX
    grid: dict[tuple[int, int, int], list[int]] = {}
    for i, s in enumerate(spheres):
        grid.setdefault(tuple(int(math.floor(v / h)) for v in s[:3]), []).append(i)
    pairs = 0
    for i, s in enumerate(spheres):
        c = tuple(int(math.floor(v / h)) for v in s[:3])
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                for dk in (-1, 0, 1):
                    for j in grid.get((c[0] + di, c[1] + dj, c[2] + dk), ()):
                        if j > i:
                            q = spheres[j]
                            d2 = sum((s[k] - q[k]) ** 2 for k in range(3))
                            if d2 < (s[3] + q[3]) ** 2:
                                pairs += 1
    return 2.0 * pairs / len(spheres), pairs


def end_state(spheres, side: float, lid_z: float, lid_force: float, n: int) -> dict:
    vol = sum(4.0 / 3.0 * math.pi * s[3] ** 3 for s in spheres)
    z, pairs = coordination(spheres)
    inside = sum(1 for s in spheres if -0.5 * s[3] < s[0] < side + 0.5 * s[3]
                 and -0.5 * s[3] < s[1] < side + 0.5 * s[3] and -0.5 * s[3] < s[2] < lid_z)
    # a sphere above the lid or outside a side has escaped the test
    return {"spheres_inside": inside, "spheres_lost": n - inside,
            "lid_height": lid_z, "porosity": 1.0 - vol / (side * side * lid_z),
            "coordination": z, "sphere_pairs": pairs, "lid_force": lid_force,
            "lid_force_target": STRESS * side * side}


# ----------------------------------------------------------------------------- qdem

def qdem_scene(side: float, dt: float, t_end: float, z_lid: float) -> str:
    walls = [([0, 0, 0], [0, 0, 1], None), ([0, 0, 0], [1, 0, 0], 0.0),
             ([side, 0, 0], [-1, 0, 0], 0.0), ([0, 0, 0], [0, 1, 0], 0.0),
             ([0, side, 0], [0, -1, 0], 0.0)]
    lines = ["# written by qdem-bench/scripts/oedometer_compare.py: fixtures/oedometer/load.toml",
             "# with a LIGGGHTS user's grains (3,000 spheres of 8-12 mm, E = 50 MPa, Hertz)",
             "[run]", f"t_end = {fmt(t_end)}", f"dt = {fmt(dt)}", "gravity = [0.0, 0.0, -9.81]",
             "probe_every = 0.005", "",
             "[[material]]", 'name = "grain"', f"density = {fmt(DENSITY)}",
             f"young = {fmt(YOUNG)}", f"poisson = {fmt(POISSON)}", "",
             "[contact]", 'law = "hertz-mindlin"', f"friction = {fmt(FRICTION)}",
             f"restitution = {fmt(RESTITUTION)}", "",
             "[granular]", 'name = "bed"', 'material = "grain"', 'sample = "insert.csv"', "",
             "[[probe]]", 'name = "all"', 'body = "bed"',
             f"box = [[-1.0, -1.0, -1.0], [{fmt(side + 1)}, {fmt(side + 1)}, {fmt(z_lid + 1)}]]",
             ""]
    for p, nrm, mu in walls:
        lines += ["[[wall]]", f"point = [{', '.join(fmt(v) for v in p)}]",
                  f"normal = [{', '.join(fmt(v) for v in nrm)}]"]
        if mu is not None:
            lines.append(f"friction = {fmt(mu)}")
        lines.append("")
    lines += ["[[wall]]", f"point = [0.0, 0.0, {fmt(z_lid)}]", "normal = [0.0, 0.0, -1.0]",
              f"servo = {{ stress = {fmt(STRESS)}, area = {fmt(side * side)}, "
              f"max_velocity = {fmt(VMAX)} }}", "",
              "[output]", 'dir = "qdem"']
    return "\n".join(lines) + "\n"


def read_csv(path: Path) -> list[dict]:
    with open(path) as f:
        head = f.readline().strip().split(",")
        return [dict(zip(head, map(float, line.split(",")))) for line in f if line.strip()]


def run_qdem(exe: Path, d: Path, side: float, pts, dt: float, seconds: float,
             threads: int) -> dict:
    with open(d / "insert.csv", "w") as f:
        f.write("stone,x,y,z,radius\n")
        for i, (x, y, z, r) in enumerate(pts, 1):
            f.write(f"{i},{x:.17e},{y:.17e},{z:.17e},{r:.17e}\n")
    scene = d / "qdem.toml"
    scene.write_text(qdem_scene(side, dt, seconds, lid_start(pts)))
    check = subprocess.run([str(exe), "check", str(scene)], cwd=d, capture_output=True, text=True)
    (d / "qdem_check.stdout").write_text(check.stdout + check.stderr)
    p = subprocess.run([str(exe), "run", str(scene), "--yes", "--threads", str(threads)],
                       cwd=d, capture_output=True, text=True)
    (d / "qdem_run.stdout").write_text(p.stdout + p.stderr)
    if p.returncode != 0:
        return {"code": "qdem", "dt": dt, "accepted": False, "refusal": (p.stdout + p.stderr)[-2000:]}
    summary = json.loads((d / "qdem" / "summary.json").read_text())
    probes = read_csv(d / "qdem" / "probes.csv")
    walls = read_csv(d / "qdem" / "walls.csv")
    stones = pcmp.read_stones(d / "qdem" / "stones.csv")
    lid_z = walls[-1]["wall6.z"]  # PFC's servo holds its target without ringing: the last row
    touched = next((w["time"] for w in walls if abs(w["wall6.fz"]) > 0), None)
    ke_after = [r["all.ke"] for r in probes if touched is not None and r["time"] >= touched]
    r = {"code": "qdem", "dt": summary["dt"], "accepted": True, "steps": summary["steps"],
         "stable_dt_estimate": summary.get("stable_dt"), "wall_s": summary["wall_seconds"],
         "kinetic_energy_end": summary["kinetic_energy"],
         "kinetic_energy_max_after_lid_touch": max(ke_after) if ke_after else None,
         "lid_first_touch_s": touched,
         "warnings": [l for l in (check.stdout + check.stderr + p.stderr).splitlines()
                      if "warn" in l.lower()][:5]}
    r.update(end_state([s[1:] for s in stones], side, lid_z, abs(walls[-1]["wall6.fz"]), len(pts)))
    return r


# ----------------------------------------------------------------------------- LIGGGHTS

def write_lid_stl(path: Path, side: float) -> None:
    """A square over the box and a diameter beyond its sides (no gap at the walls for a sphere
    to pass), at z = 0, two triangles, normals down (towards the grains)."""
    a, b = -D_MAX, side + D_MAX
    tris = [((a, a, 0), (b, b, 0), (b, a, 0)), ((a, a, 0), (a, b, 0), (b, b, 0))]
    with open(path, "w") as f:
        f.write("solid lid\n")
        for t in tris:
            f.write("  facet normal 0 0 -1\n    outer loop\n")
            for v in t:
                f.write(f"      vertex {fmt(v[0])} {fmt(v[1])} {fmt(v[2])}\n")
            f.write("    endloop\n  endfacet\n")
        f.write("endsolid lid\n")


def run_liggghts(exe: str, d: Path, side: float, pts, dt: float, seconds: float) -> dict:
    ld = d / "liggghts"
    ld.mkdir(exist_ok=True)
    top = lid_start(pts)
    with open(ld / "insert.data", "w") as f:
        f.write(f"oedometer, oedometer_compare.py\n\n{len(pts)} atoms\n3 atom types\n\n")
        pad = 2 * D_MAX
        f.write(f"{fmt(-pad)} {fmt(side + pad)} xlo xhi\n{fmt(-pad)} {fmt(side + pad)} ylo yhi\n")
        f.write(f"{fmt(-pad)} {fmt(top + pad)} zlo zhi\n\nAtoms\n\n")
        for i, (x, y, z, r) in enumerate(pts, 1):
            f.write(f"{i} 1 {fmt(2 * r)} {fmt(DENSITY)} {fmt(x)} {fmt(y)} {fmt(z)}\n")
    write_lid_stl(ld / "lid.stl", side)
    target = STRESS * side * side
    # PID, proportional: v = v_max kp (F - F_t) / F_t along the axis (down), kp = 1: the lid
    # approaches at v_max as qdem's does, and near the target its force gain v_max / F_t holds
    # (v_max 1 m/s rang at the step: 124-138 N for an 83 N target on 300 spheres)
    kp = 1.0
    e = YOUNG
    subs = {"DATA": "insert.data", "E": fmt(e), "E_WALL": fmt(e * lc.E_WALL_FACTOR),
            "NU": fmt(POISSON), "REST": fmt(RESTITUTION), "MU": fmt(FRICTION), "DT": fmt(dt),
            "SIDE": fmt(side), "HALF": fmt(0.5 * side), "LID_Z": fmt(top), "TARGET": fmt(target),
            "VMAX": fmt(VMAX), "KP": fmt(kp), "STEPS": math.ceil(seconds / dt),
            "THERMO": max(1, round(0.005 / dt)), "SKIN": fmt(0.25 * D_MIN)}
    deck = pcmp.fill(HERE / "liggghts" / "oedometer.in.template", subs, ld / "in.oedometer")
    cmd = [exe, "-in", deck.name, "-log", "log.liggghts", "-nocite"]
    p = subprocess.run(cmd, cwd=ld, capture_output=True, text=True,
                       env=dict(os.environ, OMP_NUM_THREADS="1"))
    (ld / "liggghts.stdout").write_text(p.stdout + p.stderr)
    if p.returncode != 0:
        return {"code": "liggghts", "dt": dt, "accepted": False,
                "refusal": (p.stdout + p.stderr)[-2000:]}
    thermo = []
    lines = p.stdout.splitlines()
    for i, line in enumerate(lines):
        if line.split()[:1] == ["Step"]:
            # LIGGGHTS cuts a long column name to its width ("lidavg[1" for f_lidavg[1])
            names = [c + "]" if "[" in c and not c.endswith("]") else c for c in line.split()]
            for row in lines[i + 1:]:
                v = row.split()
                if len(v) != len(names) or not v[0].isdigit():
                    break
                thermo.append(dict(zip(names, map(float, v))))
    touched = next((t["Step"] * dt for t in thermo if abs(t.get("lid[3]", 0.0)) > 0), None)
    ke = [t["ket"] + t["erot"] for t in thermo
          if touched is not None and t["Step"] * dt >= touched and "ket" in t]
    spheres = []
    with open(ld / "final.dump") as f:
        rows = f.read().splitlines()
    start = next(i for i, l in enumerate(rows) if l.startswith("ITEM: ATOMS")) + 1
    for l in rows[start:]:
        v = l.split()
        if len(v) >= 5:
            spheres.append(tuple(float(x) for x in v[1:5]))
    last = thermo[-1]
    r = {"code": "liggghts", "dt": dt, "accepted": True, "steps": subs["STEPS"],
         "kinetic_energy_end": last["ket"] + last["erot"],
         "kinetic_energy_max_after_lid_touch": max(ke) if ke else None,
         "lid_first_touch_s": touched, "servo_kp": kp}
    r.update(end_state(spheres, side, last["lidavg[2]"], abs(last["lidavg[1]"]), len(pts)))
    r["lid_force_last_step"] = abs(last["lid[3]"])
    return r


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spheres", type=int, default=3000)
    ap.add_argument("--dt", type=float, default=2e-5)
    ap.add_argument("--seconds", type=float, default=2.0)
    ap.add_argument("--work", default="out/oedometer_peers")
    ap.add_argument("--threads", type=int, default=2, help="qdem's (LIGGGHTS runs on one rank)")
    ap.add_argument("--qdem", default=str(ROOT / "target" / "release" / "qdem"))
    args = ap.parse_args()
    work = Path(args.work) if Path(args.work).is_absolute() else ROOT / args.work
    work.mkdir(parents=True, exist_ok=True)
    qdem = work / "qdem-bin"
    shutil.copy2(args.qdem, qdem)
    liggghts = lc.ensure_liggghts()
    side, pts = insertion(args.spheres)
    log(f"{len(pts)} spheres in a {side:.4f} m box, lid from z = {lid_start(pts):.4f} m")
    rows = [run_qdem(qdem, work, side, pts, args.dt, args.seconds, args.threads),
            run_liggghts(liggghts, work, side, pts, args.dt, args.seconds)]
    doc = {"machine": lc.cpu_model(), "spheres": len(pts), "box_side": side, "dt": args.dt,
           "seconds": args.seconds, "versions": {"liggghts": lc.liggghts_version(liggghts)},
           "rows": rows}
    (work / "oedometer_compare.json").write_text(json.dumps(doc, indent=2) + "\n")
    cols = ["accepted", "kinetic_energy_max_after_lid_touch", "kinetic_energy_end", "spheres_lost",
            "porosity", "coordination", "lid_force", "lid_force_target", "lid_height"]
    print("| code | " + " | ".join(cols) + " |")
    print("| --- " * (len(cols) + 1) + "|")
    for r in rows:
        print(f"| {r['code']} | " + " | ".join(
            f"{r[c]:.4g}" if isinstance(r.get(c), float) else str(r.get(c)) for c in cols) + " |")


if __name__ == "__main__":
    main()
