#!/usr/bin/env python3
"""The kernel against a previous build of it, side by side: `qdem bench --json` of two
binaries in turn (A B A B ..., so that the machine's drift hits both alike), and per size,
material and thread count the median throughput of each and the median of the pair-by-pair
ratios NEW/OLD. Prints one JSON document.

    python3 qdem-bench/scripts/kernel_vs_previous.py OLD_QDEM NEW_QDEM [--pairs 3] \
        [--tets 100000,1000000] [--threads 1,2]
"""
import argparse
import json
import statistics
import subprocess


def bench(binary, tets, threads):
    out = subprocess.run(
        [binary, "bench", "--json", "--tets", tets, "--threads", threads],
        check=True, capture_output=True, text=True,
    ).stdout
    doc = json.loads(out)
    rates = {
        (r["tets"], r["material"], r["threads"]): r["tet_steps_per_second"]
        for r in doc["results"]
    }
    triad = {b["threads"]: b["value"] for b in doc["triad_bandwidth_bytes_per_second"]}
    return rates, triad, doc


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("old")
    p.add_argument("new")
    p.add_argument("--pairs", type=int, default=3)
    p.add_argument("--tets", default="100000,1000000")
    p.add_argument("--threads", default="1,2")
    a = p.parse_args()
    runs = {"old": [], "new": []}
    for _ in range(a.pairs):
        for name in ("old", "new"):
            runs[name].append(bench(getattr(a, name), a.tets, a.threads))
    rows = []
    for key in sorted(runs["new"][0][0]):
        old = [r[0][key] for r in runs["old"]]
        new = [r[0][key] for r in runs["new"]]
        triad = [r[1][key[2]] for r in runs["new"]]
        bytes_new = next(
            x["bytes_per_tet_step"] for x in runs["new"][0][2]["results"]
            if (x["tets"], x["material"], x["threads"]) == key
        )
        rows.append({
            "tets": key[0], "material": key[1], "threads": key[2],
            "old_tet_steps_per_second": statistics.median(old),
            "new_tet_steps_per_second": statistics.median(new),
            "ratio_new_over_old": statistics.median(n / o for n, o in zip(new, old)),
            "new_bytes_per_tet_step": bytes_new,
            "triad_bytes_per_second": statistics.median(triad),
            "new_fraction_of_triad": statistics.median(
                n * bytes_new / t for n, t in zip(new, triad)),
        })
    cpu = runs["new"][0][2]["machine"]
    print(json.dumps({"machine": cpu, "pairs": a.pairs, "rows": rows}, indent=2))


if __name__ == "__main__":
    main()
