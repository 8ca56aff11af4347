"""Monte Carlo of the seed beam's ultimate load: runs seed-mc.toml (locally, or on a Dask
cluster with --dask ADDRESS), then writes the table, a histogram of the ultimate load and
the empirical fragility curve (docs/sweeps.md, "Example").

    python seed_mc.py [--samples N] [--workers N | --dask ADDRESS] [-o OUT]
"""

import argparse
import time
from pathlib import Path

import numpy as np

from segfem.sweep import Sweep

HERE = Path(__file__).resolve().parent


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, help="fewer cases than the file's 500 (a short run)")
    ap.add_argument("--workers", type=int)
    ap.add_argument("--dask", metavar="ADDRESS")
    ap.add_argument("-o", "--output", default=str(HERE / "seed-mc"))
    ap.add_argument("--report", action="store_true", help="no runs: the table and figures of the cases finished so far")
    a = ap.parse_args()
    sweep = Sweep.load(HERE / "seed-mc.toml")
    if a.samples:
        sweep.samples = a.samples
    out = Path(a.output)
    t0 = time.perf_counter()

    def show(done, total, rec):
        r = rec["result"]
        print(f"[{done}/{total}] case {rec['case']}: {r['status']}, Q_u = {r.get('ultimate_factor')}, {r['elapsed_s']:.2f} s", flush=True)

    if a.report:
        table = sweep.gather(out)
    else:
        table = sweep.run(out, workers=a.workers, scheduler=a.dask, progress=show)
    wall = time.perf_counter() - t0
    ok = table[table["ultimate_factor"].notna()]
    # The load factor of case Q is the load at each of the two load points [kN].
    qu = ok["ultimate_factor"].to_numpy()
    if not a.report:
        print(f"{len(table)} cases ({len(ok)} with an ultimate verdict) in {wall:.0f} s on this machine")
    print(f"mean time per case {table['elapsed_s'].mean():.2f} s (segfem's own wall time {table['wall_s'].mean():.2f} s)")
    print(f"Q_u [kN]: mean {qu.mean():.2f}, std {qu.std(ddof=1):.3f}, min {qu.min():.2f}, max {qu.max():.2f}")
    print("failure modes:", ok["ultimate_mode"].value_counts().to_dict())
    for name in ("fcm", "sigma_p0", "friction"):
        print(f"correlation Q_u ~ {name}: {np.corrcoef(ok[name], qu)[0, 1]:+.2f}")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no figures")
        return
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    ax[0].hist(qu, bins=30, color="#4477aa")
    ax[0].set_xlabel("ultimate load Q_u per load point [kN]")
    ax[0].set_ylabel("cases")
    ax[0].set_title(f"seed beam, {len(qu)} Monte Carlo runs")
    ax[0].ticklabel_format(useOffset=False)
    q = np.sort(qu)
    # Empirical fragility: P(failure | Q) = share of cases whose capacity is at most Q.
    ax[1].step(q, np.arange(1, len(q) + 1) / len(q), where="post", color="#aa3377")
    ax[1].set_xlabel("applied load Q per load point [kN]")
    ax[1].set_ylabel("P(failure | Q)")
    ax[1].set_title("empirical fragility curve")
    ax[1].grid(alpha=0.3)
    ax[1].ticklabel_format(axis="x", useOffset=False)
    fig.tight_layout()
    fig.savefig(out / "seed-mc.png", dpi=120)
    fig.savefig(out / "seed-mc.svg")
    print(f"figures: {out / 'seed-mc.png'}, {out / 'seed-mc.svg'}")


if __name__ == "__main__":
    main()
