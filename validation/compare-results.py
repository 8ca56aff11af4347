#!/usr/bin/env python3
"""Compare every bundled example's results between two segfem binaries, within tolerances.

`validation/compare-examples.sh` proves a change bit-identical. A change that cannot be
(another factorisation ordering, another Newton start) needs the next question answered:
are the answers the same within what the solver's tolerance allows? For each example this
runs both binaries on the same model file and prints, per side, the status, the `ultimate`
verdict, increments and Newton iterations, and for the three history columns that differ
most: the difference of their largest values and of their final values, each relative to
the larger of the two largest values.

Usage: validation/compare-results.py BIN_A BIN_B [EXAMPLE ...] [--peak-tol 5e-3]

Exit status 0 when every example has the same status and verdict on both sides and every
column's largest value agrees within --peak-tol (default 0.5 %, relative); 1 otherwise;
2 on bad usage. Local history values (largest crack or plastic strain) move more than the
loads on cracking models: read the printed columns, not only the status.
"""
import argparse
import csv
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

SKIP = {"step", "increment", "iterations"}


def run(binary, model, out):
    subprocess.run([binary, "run", "-q", str(model), "-o", str(out)], capture_output=True)
    try:
        rows = list(csv.DictReader(open(out / "history.csv")))
        summary = json.load(open(out / "summary.json"))
    except (OSError, ValueError) as e:
        sys.exit(f"{binary}: {model.name}: no results ({e})")
    return rows, summary


def column(rows, name):
    values = []
    for r in rows:
        try:
            v = float(r[name])
        except (TypeError, ValueError):
            continue
        if math.isfinite(v):
            values.append(v)
    return values


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("bin_a")
    ap.add_argument("bin_b")
    ap.add_argument("examples", nargs="*")
    ap.add_argument("--peak-tol", type=float, default=5e-3)
    a = ap.parse_args()
    for b in (a.bin_a, a.bin_b):
        if not Path(b).is_file():
            print(f"error: {b} is not a file", file=sys.stderr)
            return 2
    names = a.examples or [
        line.split()[0]
        for line in subprocess.run([a.bin_a, "example"], capture_output=True, text=True).stdout.splitlines()
        if line.strip()
    ]
    status = 0
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for name in names:
            model = work / f"{name}.toml"
            subprocess.run([a.bin_a, "example", name, "-o", str(model)], capture_output=True, check=True)
            ra, sa = run(a.bin_a, model, work / f"a_{name}")
            rb, sb = run(a.bin_b, model, work / f"b_{name}")
            diffs = []
            for col in ra[0].keys() if ra else []:
                if col in SKIP:
                    continue
                ca, cb = column(ra, col), column(rb, col)
                if not ca or not cb:
                    continue
                pa, pb = max(ca, key=abs), max(cb, key=abs)
                scale = max(abs(pa), abs(pb))
                if scale == 0.0:
                    continue
                diffs.append((abs(pa - pb) / scale, abs(ca[-1] - cb[-1]) / scale, col, pa, pb))
            diffs.sort(reverse=True)
            ua, ub = sa.get("ultimate") or {}, sb.get("ultimate") or {}
            va, vb = ua.get("mode"), ub.get("mode")
            ta, tb = sa["timings"], sb["timings"]
            ok = sa["status"] == sb["status"] and va == vb and all(d[0] <= a.peak_tol for d in diffs)
            status |= 0 if ok else 1
            print(
                f"{name}: {'same' if ok else 'DIFFERENT'}: status {sa['status']} / {sb['status']}, "
                f"verdict {va} / {vb}, increments {ta['increments']} / {tb['increments']}, "
                f"iterations {ta['iterations']} / {tb['iterations']}"
            )
            for d in diffs[:3]:
                print(f"    {d[2]}: largest {d[3]:.7g} / {d[4]:.7g} (rel. diff. {d[0]:.1e}), final rel. diff. {d[1]:.1e}")
    return status


if __name__ == "__main__":
    sys.exit(main())
