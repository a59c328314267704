#!/usr/bin/python3
"""Scaling of the MPI lattice Boltzmann fluid step (bench/mpi/bench_lbm_mpi.cpp), for docs/mpi.md.

Runs, each under `nice mpirun --oversubscribe -np P`:
  weak scaling:   64 x 64 x 64 nodes per rank (the lattice grows in y), P = 1, 2, 4, 20 steps;
  strong scaling: a 128^3 box, P = 1, 2, 4, 5 steps;
prints the measurements (seconds per step of the slowest rank, the halo exchange's share, halo
bytes sent per rank and step) and, next to them, the parallel efficiency that the communication
volume predicts on a cluster network: t_step(P) = t_1 / P + 2 (L + b / B), b = 5 nx nz 8 bytes per
face message (two exchanges of the two faces at once per step), with the single-rank time t_1
measured here, latency L and bandwidth B below (no overlap of computation and communication).
Usage: mpi_scaling.py BUILD_DIR [--quick]
"""
import json
import os
import subprocess
import sys

LATENCY = 1.5e-6      # s, one MPI message on InfiniBand HDR/EDR
BANDWIDTH = 12.5e9    # B/s, 100 Gb/s per direction


def run(bench, ranks, nx, ny, nz, steps, weak):
    cmd = ["nice", "-n", "10", "mpirun", "--oversubscribe", "-np", str(ranks), bench, str(nx), str(ny), str(nz),
           str(steps)] + (["weak"] if weak else [])
    env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env).stdout
    return json.loads(out.strip().splitlines()[-1])


def predicted_efficiency(t1, nx, nz, ranks):
    if ranks == 1:
        return 1.0
    b = 5 * nx * nz * 8
    t_comm = 2 * (LATENCY + b / BANDWIDTH)
    return (t1 / ranks) / (t1 / ranks + t_comm)


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build/release"
    quick = "--quick" in sys.argv
    bench = os.path.join(build, "bench_lbm_mpi")
    print(f"# cores: {os.cpu_count()} (ranks above that are oversubscribed)")
    print("# weak scaling: 64 x 64 x 64 per rank")
    print("ranks  lattice          s/step   halo s/step  MLUPS  halo B/rank/step  efficiency")
    base = None
    for p in (1, 2, 4):
        r = run(bench, p, 64, 64, 64, 5 if quick else 20, True)
        base = base or r["seconds_per_step"]
        print(f"{p:5d}  {'x'.join(map(str, r['lattice'])):15s}  {r['seconds_per_step']:.4f}   {r['halo_seconds_per_step']:.5f}"
              f"      {r['mlups']:5.1f}  {r['halo_bytes_per_rank_step']:16.0f}  {base / r['seconds_per_step']:.2f}")
    print("# strong scaling: 128^3")
    print("ranks  s/step   halo s/step  MLUPS  halo B/rank/step  speed-up  efficiency  predicted (cluster)")
    t1 = None
    for p in (1, 2, 4):
        r = run(bench, p, 128, 128, 128, 2 if quick else 5, False)
        t1 = t1 or r["seconds_per_step"]
        s = t1 / r["seconds_per_step"]
        print(f"{p:5d}  {r['seconds_per_step']:.4f}   {r['halo_seconds_per_step']:.5f}      {r['mlups']:5.1f}  "
              f"{r['halo_bytes_per_rank_step']:16.0f}  {s:8.2f}  {s / p:10.2f}  {predicted_efficiency(t1, 128, 128, p):.3f}")
    print(f"# predicted strong-scaling efficiency of 128^3 with L = {LATENCY * 1e6:g} us, B = {BANDWIDTH / 1e9:g} GB/s, "
          f"t_1 = {t1:.3f} s measured here:")
    for p in (8, 16, 32, 64, 128):
        print(f"#   P = {p:3d}: {predicted_efficiency(t1, 128, 128, p):.3f}")


if __name__ == "__main__":
    main()
