#!/usr/bin/env python3
"""The fault probe of docs/reliability.md: runs a small scene (the contact collision, 0.5 s)
through the faults a user's machine deals it and counts what was lost.

    python3 scripts/reliability_probe.py QDEM [--trials N] [--families locks,signals,...]

Families (each trial in a fresh folder under a temporary directory):
- locks: two runs started together into one folder whose `.qdem-run.lock` was left empty,
  holding garbage, the pid of a process that has ended, the pid of a live process that is
  no qdem run, or no lock at all. Passes when exactly one run writes the folder and the
  other is refused with a message naming the lock, and the folder holds the first run's
  complete outputs only.
- signals: SIGKILL, SIGTERM or SIGINT at a random moment, then `--resume` from the
  checkpoint (or a fresh run where none was written). Passes when the resumed run's
  `probes.csv`, `poses.csv` and VTUs are byte-identical to an uninterrupted run's.
- checkpoints: a finished run's checkpoint cut short, a byte flipped, zeroed or replaced by
  text, then resumed. Passes when the resume is refused with a message (exit 1), never a
  panic (101) or an abort (134).
- disk: the run into a 64 KiB tmpfs (needs root; skipped otherwise). Passes when the run
  fails with a message and leaves no file it started half-written.

Prints one JSON line per family with its trials and failures, then a Markdown table. Exits
non-zero when any trial failed.
"""

import argparse
import filecmp
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENE_FILES = ["collision.toml", "block.msh", "ramp.msh"]


def scene_dir(base, name, vtu_every="0.005"):
    """A copy of the collision scene in base/name writing to ./out with checkpoints."""
    d = base / name
    d.mkdir(parents=True)
    for f in SCENE_FILES:
        shutil.copy(ROOT / "fixtures/contact" / f, d / f)
    text = (d / "collision.toml").read_text()
    text = text.replace('dir = "out/collision"', 'dir = "out"')
    text = text.replace("vtu_every = 0.005", f"vtu_every = {vtu_every}\ncheckpoint_every = 0.005")
    (d / "collision.toml").write_text(text)
    return d


def run(qdem, d, *args, out=None):
    cmd = [qdem, "run", str(d / "collision.toml"), *args]
    if out is not None:
        cmd += ["--out", str(out)]
    return subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, CI="true"))


def outputs(out):
    """The files compared between runs: probes, poses, VTUs."""
    files = [p for p in ["probes.csv", "poses.csv"] if (out / p).exists()]
    files += sorted(str(p.relative_to(out)) for p in (out / "vtu").glob("*.vtu"))
    return files


def same_outputs(a, b):
    fa, fb = outputs(a), outputs(b)
    return fa == fb and all(filecmp.cmp(a / f, b / f, shallow=False) for f in fa)


def dead_pid():
    p = subprocess.Popen(["true"])
    p.wait()
    return p.pid


def lock_trial(qdem, base, kind, k):
    """Two runs (VTUs every 5 ms and every 10 ms) into one folder with a stale lock."""
    a = scene_dir(base, f"lock-{kind}-{k}-a", "0.005")
    b = scene_dir(base, f"lock-{kind}-{k}-b", "0.01")
    out = base / f"lock-{kind}-{k}-out"
    out.mkdir()
    sleeper = None
    content = {
        "empty": "",
        "garbage": "not a pid \x00\xff",
        "dead": f"{dead_pid()}\n",
        "none": None,
    }.get(kind)
    if kind == "live":
        sleeper = subprocess.Popen(["sleep", "30"])
        content = f"{sleeper.pid}\n"
    if content is not None:
        (out / ".qdem-run.lock").write_text(content, errors="surrogateescape")
    cmd = lambda d: [qdem, "run", str(d / "collision.toml"), "--out", str(out)]
    env = dict(os.environ, CI="true")
    pa = subprocess.Popen(cmd(a), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    pb = subprocess.Popen(cmd(b), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    ra, rb = pa.communicate(), pb.communicate()
    if sleeper:
        sleeper.kill()
    codes = (pa.returncode, pb.returncode)
    winners = [i for i, c in enumerate(codes) if c == 0]
    refused = [i for i, (c, r) in enumerate(zip(codes, (ra, rb))) if c != 0 and "in use" in r[1]]
    if len(winners) != 1 or len(refused) != 1:
        return f"exits {codes}: {ra[1].strip()[-200:]} | {rb[1].strip()[-200:]}"
    # The folder holds the winner's outputs only: its VTU count.
    vtus = len(list((out / "vtu").glob("state_*.vtu")))
    want = 11 if winners[0] == 0 else 6
    if vtus != want:
        return f"run {'ab'[winners[0]]} won but the folder holds {vtus} state VTUs, not {want}"
    return None


def signal_trial(qdem, base, sig, k, reference):
    d = scene_dir(base, f"sig-{sig.name}-{k}")
    out = d / "out"
    p = subprocess.Popen(
        [qdem, "run", str(d / "collision.toml")],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=dict(os.environ, CI="true"),
    )
    time.sleep(random.uniform(0.02, 0.45))
    p.send_signal(sig)
    p.wait()
    ckpt = out / "checkpoint.qdc"
    r = run(qdem, d, "--resume", str(ckpt)) if ckpt.exists() else run(qdem, d)
    if r.returncode != 0:
        return f"exit {p.returncode}, then the resume exited {r.returncode}: {r.stderr.strip()[-300:]}"
    if not same_outputs(out, reference):
        return f"exit {p.returncode}; resumed outputs differ from the uninterrupted run's"
    return None


def damage(data, how, rng):
    if how == "cut":
        return data[: rng.randrange(0, len(data))]
    if how == "flip":
        i = rng.randrange(0, len(data))
        return data[:i] + bytes([data[i] ^ (1 << rng.randrange(8))]) + data[i + 1 :]
    if how == "zero":
        return bytes(len(data))
    return b"this is not a checkpoint\n" * rng.randrange(1, 50)


def checkpoint_trial(qdem, base, how, k, rng):
    d = scene_dir(base, f"ckpt-{how}-{k}")
    first = run(qdem, d)
    if first.returncode != 0:
        return f"the undamaged run failed: {first.stderr.strip()[-300:]}"
    ckpt = d / "out" / "checkpoint.qdc"
    ckpt.write_bytes(damage(ckpt.read_bytes(), how, rng))
    r = run(qdem, d, "--resume", str(ckpt))
    if r.returncode != 1 or "panicked" in r.stderr or not r.stderr.strip():
        return f"exit {r.returncode}: {r.stderr.strip()[-300:]}"
    return None


def disk_trial(qdem, base, k):
    d = scene_dir(base, f"disk-{k}")
    mnt = base / f"disk-{k}-mnt"
    mnt.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mnt)],
                      capture_output=True).returncode != 0:
        return "skip"
    try:
        r = run(qdem, d, out=mnt)
        if r.returncode == 0:
            return "a run into a full disk exited 0"
        if r.returncode in (101, 134) or not r.stderr.strip():
            return f"exit {r.returncode}: {r.stderr.strip()[-300:]}"
        tmp = [p.name for p in mnt.rglob("*") if ".tmp-" in p.name or ".publish-" in p.name]
        if tmp:
            return f"temporary files left: {tmp}"
        return None
    finally:
        subprocess.run(["umount", str(mnt)])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("qdem")
    ap.add_argument("--trials", type=int, default=5)
    ap.add_argument("--families", default="locks,signals,checkpoints,disk")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    qdem = str(Path(args.qdem).resolve())
    rng = random.Random(args.seed)
    random.seed(args.seed)
    rows, failed = [], 0
    with tempfile.TemporaryDirectory(prefix="qdem-probe-") as tmp:
        base = Path(tmp)
        plan = []
        families = args.families.split(",")
        if "locks" in families:
            for kind in ["empty", "garbage", "dead", "live", "none"]:
                plan.append((f"locks: {kind}", lambda k, kind=kind: lock_trial(qdem, base, kind, k)))
        if "signals" in families:
            ref = scene_dir(base, "reference")
            if run(qdem, ref).returncode != 0:
                sys.exit("the uninterrupted reference run failed")
            for sig in [signal.SIGKILL, signal.SIGTERM, signal.SIGINT]:
                plan.append((f"signals: {sig.name}",
                             lambda k, sig=sig: signal_trial(qdem, base, sig, k, ref / "out")))
        if "checkpoints" in families:
            for how in ["cut", "flip", "zero", "text"]:
                plan.append((f"checkpoints: {how}",
                             lambda k, how=how: checkpoint_trial(qdem, base, how, k, rng)))
        if "disk" in families:
            plan.append(("disk: 64 KiB", lambda k: disk_trial(qdem, base, k)))
        for name, trial in plan:
            results = [trial(k) for k in range(args.trials)]
            skipped = sum(r == "skip" for r in results)
            fails = [r for r in results if r not in (None, "skip")]
            failed += len(fails)
            row = {"case": name, "trials": len(results) - skipped, "failed": len(fails),
                   "skipped": skipped, "first_failure": fails[0] if fails else None}
            rows.append(row)
            print(json.dumps(row), flush=True)
    print("\n| case | trials | failed | first failure |\n| --- | --- | --- | --- |")
    for r in rows:
        print(f"| {r['case']} | {r['trials']} | {r['failed']} | {r['first_failure'] or '—'} |")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
