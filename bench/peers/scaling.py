#!/usr/bin/env python3
"""Scaling of segfem's run time with the model size (issue 21 item 5).

Runs `segfem run` on the linear square of bench/peers/peers.py (Q4 and Q8, one linear
step, the default output) and on the RC beam example refined r times (nonlinear, to 24 mm
at the plate, bench/peers/nonlinear.py's input), records wall and CPU time (user +
system) of the whole process, Newton iterations, and fits t = a · dofs^b by least squares
on the logarithms (linear: sizes from 1e4 dofs, below which process start-up dominates).
Optionally adds OpenSees on the linear square. Writes a log-log figure (matplotlib of the
peers venv) and prints a markdown table.

    bench/peers/.venv/bin/python bench/peers/scaling.py \
        --linear 1e3,1e4,1e5,1e6 --refine 1,2,3 --opensees 1e3,1e4,1e5 \
        --png docs/img/scaling.png --json bench/peers/work/scaling.json
"""

import argparse
import json
import math
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import nonlinear  # noqa: E402
import peers  # noqa: E402


def fit(points):
    """Least-squares t = a n^b on log-log: (a, b)."""
    xs = [math.log(n) for n, _ in points]
    ys = [math.log(t) for _, t in points]
    mx, my = statistics.fmean(xs), statistics.fmean(ys)
    b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    return math.exp(my - b * mx), b


def run_segfem(toml, ok=(0,)):
    out = toml.parent / "segfem_out"
    wall, rss, _, _ = peers.timed([peers.segfem_bin(), "run", "-q", toml.name, "-o", out.name], toml.parent, ok=ok)
    return wall, peers.CPU_TIMES[-1], rss, out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--linear", default="1e3,1e4,1e5,1e6", help="target dofs of the linear squares")
    ap.add_argument("--elements", default="Q4,Q8")
    ap.add_argument("--refine", default="1,2,3", help="refinements of the RC beam (nonlinear)")
    ap.add_argument("--opensees", default="", help="dofs at which OpenSees runs the linear square too")
    ap.add_argument("--reps", type=int, default=2, help="runs per point below 1e5 dofs (median)")
    ap.add_argument("--png", default="")
    ap.add_argument("--json", default="")
    ap.add_argument("--replot", default="", help="only plot this JSON of an earlier run")
    ap.add_argument("--metric", default="cpu", choices=["cpu", "wall"],
                    help="plotted time: CPU (user + system, less sensitive to a shared machine's load) or wall")
    args = ap.parse_args()

    if args.replot:
        data = json.loads(Path(args.replot).read_text())
    else:
        data = {"linear": [], "nonlinear": [], "opensees": []}
        peers.WORK.mkdir(exist_ok=True)
        for kind in args.elements.split(","):
            for s in args.linear.split(","):
                dofs = int(float(s))
                n = peers.q4_n_for(dofs) if kind == "Q4" else peers.q8_n_for(dofs)
                d = peers.WORK / f"{kind.lower()}_{n}"
                files = peers.write_linear(kind, n, d)
                nodes = (n + 1) ** 2 if kind == "Q4" else (2 * n + 1) ** 2 - n * n
                reps = args.reps if dofs < 1e5 else 1
                runs = [run_segfem(files["segfem + .vtu"])[:3] for _ in range(reps)]
                row = dict(kind=kind, dofs=2 * nodes, wall=statistics.median(r[0] for r in runs),
                           cpu=statistics.median(r[1] for r in runs), rss=max(r[2] for r in runs), runs=reps)
                data["linear"].append(row)
                print("linear", row, file=sys.stderr, flush=True)
                if args.opensees and s in args.opensees.split(",") and kind == "Q4":
                    w, rss, _ = peers.run_python(files["OpenSees"])
                    o = dict(kind=kind, dofs=2 * nodes, wall=w, cpu=peers.CPU_TIMES[-1], rss=rss, runs=1)
                    data["opensees"].append(o)
                    print("opensees", o, file=sys.stderr, flush=True)
        for s in args.refine.split(","):
            r = int(s)
            files = nonlinear.write_beam(r, peers.WORK / f"nl_beam_{r}")
            nodes, _, _, _ = nonlinear.beam_mesh(r)
            wall, cpu, rss, out = run_segfem(files["segfem"])
            rows, its = nonlinear.beam_rows_segfem(out)
            row = dict(refine=r, dofs=2 * len(nodes), wall=wall, cpu=cpu, rss=rss, iterations=its,
                       increments=len(rows), peak_kN=max(p for _, p, _, _ in rows) / 1e3)
            data["nonlinear"].append(row)
            print("nonlinear", row, file=sys.stderr, flush=True)
        if args.json:
            Path(args.json).write_text(json.dumps(data, indent=1))

    lines = ["| series | points | fit: wall [s] | fit: CPU [s] |", "|---|---|---|---|"]
    series = {}
    for kind in sorted({r["kind"] for r in data["linear"]}):
        pts = [r for r in data["linear"] if r["kind"] == kind]
        series[f"segfem linear {kind}, whole run"] = pts
    if data["opensees"]:
        series["OpenSees linear Q4, whole run"] = data["opensees"]
    if data["nonlinear"]:
        series["segfem RC beam to 24 mm, whole run"] = data["nonlinear"]
        series["segfem RC beam, per Newton iteration"] = [
            dict(r, wall=r["wall"] / r["iterations"], cpu=r["cpu"] / r["iterations"]) for r in data["nonlinear"]
        ]
    if data.get("opensees_nonlinear"):
        # From bench/peers/nonlinear.py runs, added to the JSON by hand.
        series["OpenSees RC beam, per Newton iteration"] = [
            dict(r, wall=r["wall"] / r["iterations"], cpu=r["cpu"] / r["iterations"]) for r in data["opensees_nonlinear"]
        ]
    fits = {}
    for name, pts in series.items():
        use = [p for p in pts if p["dofs"] >= 1e4] if "linear" in name else pts
        if len(use) < 2:
            use = pts
        aw, bw = fit([(p["dofs"], p["wall"]) for p in use])
        ac, bc = fit([(p["dofs"], max(p["cpu"], 1e-3)) for p in use])
        fits[name] = (aw, bw, ac, bc)
        lines.append(f"| {name} | {len(use)} ({min(p['dofs'] for p in use):,}–{max(p['dofs'] for p in use):,} dofs) | "
                     f"{aw:.3g} · n^{bw:.2f} | {ac:.3g} · n^{bc:.2f} |")
    print("\n".join(lines))

    if args.png:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 5))
        marks = iter("osD^vxP")
        for name, pts in series.items():
            m = next(marks)
            xs = [p["dofs"] for p in pts]
            aw, bw, ac, bc = fits[name]
            if args.metric == "cpu":
                aw, bw = ac, bc
            ax.loglog(xs, [max(p[args.metric], 1e-3) for p in pts], m, label=name)
            lo, hi = min(xs), max(xs)
            xx = [lo * (hi / lo) ** (k / 20) for k in range(21)]
            ax.loglog(xx, [aw * x**bw for x in xx], "-", lw=0.8, color=ax.lines[-1].get_color(),
                      label=f"  fit n^{bw:.2f}")
        ax.set_xlabel("degrees of freedom n")
        ax.set_ylabel("CPU time, user + system [s]" if args.metric == "cpu" else "wall time [s]")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7)
        ax.set_title(f"run time against model size ({args.metric}; 2-core Xeon shared with other work)", fontsize=9)
        fig.tight_layout()
        fig.savefig(args.png, dpi=110)
        print(f"figure: {args.png}", file=sys.stderr)


if __name__ == "__main__":
    main()
