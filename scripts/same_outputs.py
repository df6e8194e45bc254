#!/usr/bin/env python3
"""Shows that a refactor kept behaviour: runs the quick fixture scenes with two `qdem`
binaries and compares what they wrote.

    python3 scripts/same_outputs.py BEFORE_QDEM AFTER_QDEM [--threads N] [--keep DIR]

Scenes: the cantilever lc100 (the README's main job), the contact collision and incline, the
small box tests (the cell's bed and crib deposits, the walled box's stones poured back, then
the single-sleeper boxes and the three-sleeper box on their sample), the small BBM beam and the implicit 0.025 m beam, and the
reduced ballast deposit cut to 4 ms. Every CSV, SVG, VTU and PVD file is compared byte for byte,
`summary.json` field by field without the timing fields (wall time, rates, the stage
counters, the thread and rank counts). Prints one JSON line per scene and exits non-zero on any
difference. With `--keep DIR`, the runs are kept in DIR/before and DIR/after, and a label
whose folder is already there is not run again (compare a new build against kept outputs).
With `--arrays-of-before`, a VTU file whose bytes differ is compared array by array over the
arrays the BEFORE file has (each array's name, attributes and data byte for byte): for a change
that adds arrays on purpose and must leave every other array as it was.
"""

import re

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FIX = ROOT / "fixtures"

# In run order: a box test reads the stones its deposit wrote.
SCENES = [
    "cantilever/cantilever_lc100.toml",
    "contact/collision.toml",
    "contact/incline.toml",
    "contact/grains.toml",
    "boxtest/small_deposit_cell_bed.toml",
    "boxtest/small_deposit_cell_crib.toml",
    "boxtest/small_deposit_fixed_crib.toml",
    "boxtest/small_single_fixed.toml",
    "boxtest/small_single_periodic.toml",
    "boxtest/small_single_delayed.toml",
    "boxtest/small_single_shared.toml",
    "boxtest/small_three_sleeper.toml",
    "bbm/small_beam.toml",
    "bbm/beam_implicit_0.025.toml",
    "ballast/_short_deposit.toml",
]

# The short ballast deposit: the reduced deposit to 4 ms, writing its own directory.
SHORT_DEPOSIT = ("ballast/reduced_deposit.toml", "ballast/_short_deposit.toml")


def timing_key(key):
    return (
        "seconds" in key
        or "per_second" in key
        or key in ("threads", "ranks", "stages", "scene")
    )


def strip_timing(value):
    if isinstance(value, dict):
        return {k: strip_timing(v) for k, v in value.items() if not timing_key(k)}
    if isinstance(value, list):
        return [strip_timing(v) for v in value]
    return value


def out_dir(scene):
    text = tomllib.loads(scene.read_text())
    return scene.parent / text.get("output", {}).get("dir", "out")


def make_short_deposit():
    src, dst = (FIX / p for p in SHORT_DEPOSIT)
    text = src.read_text()
    text = text.replace("t_end = 0.5", "t_end = 0.004", 1)
    text = text.replace(
        'dir = "../../out/ballast/reduced_deposit"',
        'dir = "../../out/ballast/_short_deposit"',
        1,
    )
    dst.write_text(text)
    return dst


def run_all(qdem, threads, store):
    for rel in SCENES:
        scene = FIX / rel
        out = out_dir(scene)
        shutil.rmtree(out, ignore_errors=True)
        cmd = [qdem, "run", str(scene)]
        if threads:
            cmd += ["--threads", str(threads)]
        done = subprocess.run(cmd, capture_output=True, text=True)
        if done.returncode != 0:
            sys.exit(f"{qdem} run {rel} failed:\n{done.stderr}")
        shutil.copytree(out, store / rel)


def vtu_arrays(path):
    """The `<DataArray ...>...</DataArray>` elements of a VTU file by (Name, position)."""
    text = path.read_text()
    arrays = re.findall(r'<DataArray[^>]*>.*?</DataArray>', text, flags=re.S)
    named = {}
    for k, a in enumerate(arrays):
        m = re.search(r'Name="([^"]*)"', a)
        named[(m.group(1) if m else f"#{k}")] = a
    return named


def same_arrays(a, b):
    x, y = vtu_arrays(a), vtu_arrays(b)
    return all(name in y and y[name] == array for name, array in x.items())


def compare(before, after, rel, arrays_of_before=False):
    a, b = before / rel, after / rel
    files = sorted(
        p.relative_to(a)
        for p in a.rglob("*")
        if p.is_file() and p.suffix in (".csv", ".vtu", ".pvd", ".json", ".svg")
    )
    different = []
    for f in files:
        if not (b / f).exists():
            different.append(f"{f} missing")
        elif f.suffix == ".json":
            x = strip_timing(json.loads((a / f).read_text()))
            y = strip_timing(json.loads((b / f).read_text()))
            if x != y:
                different.append(str(f))
        elif (a / f).read_bytes() != (b / f).read_bytes():
            if not (arrays_of_before and f.suffix == ".vtu" and same_arrays(a / f, b / f)):
                different.append(str(f))
    return len(files), different


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--threads", type=int, default=None)
    parser.add_argument("--keep", type=Path, default=None)
    parser.add_argument("--arrays-of-before", action="store_true")
    args = parser.parse_args()
    work = args.keep or Path(tempfile.mkdtemp(prefix="same_outputs_"))
    short = make_short_deposit()
    try:
        for label, qdem in (("before", args.before), ("after", args.after)):
            if not (work / label).exists():
                run_all(str(Path(qdem).resolve()), args.threads, work / label)
    finally:
        short.unlink()
    failed = False
    for rel in SCENES:
        count, different = compare(work / "before", work / "after", rel, args.arrays_of_before)
        failed |= bool(different) or count == 0
        print(json.dumps({"scene": rel, "files": count, "different": different}))
    if failed:
        sys.exit("outputs differ")
    print("all outputs identical (summaries without timing fields)")


if __name__ == "__main__":
    main()
