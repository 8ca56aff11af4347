#!/usr/bin/env python3
"""A B A B timing of segfem binaries on model files: wall, CPU and the phase times of
summary.json, per run and as medians (docs/performance.md, "Linear whole run against the
factorisation").

Usage: python3 bench/ab_linear.py BIN_A,BIN_B MODEL[,MODEL...] ROUNDS
Each round runs every model with every binary in turn (output in /tmp/ab-<binary name>).
"""
import json, os, statistics, subprocess, sys, time, resource
bins = sys.argv[1].split(",")
models = sys.argv[2].split(",")
rounds = int(sys.argv[3])
res = {}
for r in range(rounds):
    for m in models:
        for b in bins:
            out = f"/tmp/ab-{os.path.basename(b)}"
            t0 = time.perf_counter()
            ru0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            p = subprocess.run([b, "run", m, "-o", out], capture_output=True, text=True)
            wall = time.perf_counter() - t0
            ru1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = (ru1.ru_utime - ru0.ru_utime) + (ru1.ru_stime - ru0.ru_stime)
            s = json.load(open(f"{out}/summary.json"))
            t = s["timings"]; so = t["solver"]
            row = dict(wall=wall, cpu=cpu, input=s["input_s"], setup=t["setup_s"] - so["symbolic_s"],
                       symbolic=so["symbolic_s"], assembly=t["assembly_s"], numeric=so["numeric_s"],
                       solve=so["solve_s"], output=t["output_s"])
            load = os.getloadavg()[0]
            res.setdefault((m, b), []).append(row)
            print(f"round {r} {os.path.basename(os.path.dirname(m))} {os.path.basename(b):14s} load {load:4.1f} " + " ".join(f"{k} {v:.3f}" for k, v in row.items()), flush=True)
print("medians")
for (m, b), rows in res.items():
    med = {k: statistics.median(x[k] for x in rows) for k in rows[0]}
    print(f"{os.path.basename(os.path.dirname(m))} {os.path.basename(b):14s} n={len(rows)} " + " ".join(f"{k} {v:.3f}" for k, v in med.items()) + f" ratio wall/numeric {med['wall']/med['numeric']:.2f}")
