#!/usr/bin/python3
"""D and theta against gamma t for one `bendlab shear` run: plot_shear.py RUN_DIR -> RUN_DIR/D_theta.png"""
import csv
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main(run_dir: Path) -> None:
    with open(run_dir / "timeseries.csv") as f:
        rows = list(csv.DictReader(f))
    t = [float(r["gamma_t"]) for r in rows]
    D = [float(r["D"]) for r in rows]
    theta = [float(r["theta"]) / 3.141592653589793 for r in rows]
    summary = json.loads((run_dir / "summary.json").read_text())
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    a1.plot(t, D)
    a1.set_xlabel(r"$\dot\gamma t$")
    a1.set_ylabel("D")
    a2.plot(t, theta)
    a2.set_xlabel(r"$\dot\gamma t$")
    a2.set_ylabel(r"$\theta / \pi$")
    fig.suptitle(f"method {summary['method']}, {summary['triangles']} triangles, G = {summary['G']}, "
                 f"kB_hat = {summary['kappa_b_hat']}: D_steady = {summary['D_steady']:.4f}")
    fig.tight_layout()
    fig.savefig(run_dir / "D_theta.png", dpi=110)


if __name__ == "__main__":
    main(Path(sys.argv[1]))
