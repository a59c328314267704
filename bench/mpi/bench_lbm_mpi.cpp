// Timing of the distributed D3Q19 fluid step (parallel/distributed_lattice.hpp), for
// scripts/mpi_scaling.py and docs/mpi.md. Run under mpirun:
//   mpirun -np P bench_lbm_mpi NX NY NZ STEPS [weak]
// With "weak" NY is per rank (the lattice is NX x P NY x NZ). The fluid starts in the walls'
// shear flow with a small force field (as a capsule run's), takes 2 warm-up steps, then STEPS
// timed steps; each rank times its own steps and the slowest rank's time counts. Prints one JSON
// line on rank 0: ranks, lattice, seconds per step (compute = the local step, halo = the exchange
// included in it), MLUPS, halo bytes sent per rank per step.
#include <mpi.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "bendlab/parallel/distributed_lattice.hpp"

using namespace bendlab;

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (argc < 5) {
    if (rank == 0) std::fprintf(stderr, "usage: bench_lbm_mpi NX NY NZ STEPS [weak]\n");
    MPI_Finalize();
    return 2;
  }
  const bool weak = argc > 5 && std::string(argv[5]) == "weak";
  lbm::LatticeConfig c;
  c.nx = std::atoi(argv[1]);
  c.ny = std::atoi(argv[2]) * (weak ? size : 1);
  c.nz = std::atoi(argv[3]);
  c.tau = 1.0;
  c.walls = true;
  c.wall_velocity = 0.01;
  const int steps = std::atoi(argv[4]);
  try {
    parallel::DistributedLattice d(c, MPI_COMM_WORLD);
    d.initialise_shear_flow();
    d.local().set_uniform_force(Vec3(1e-6, 0, 0));
    for (int s = 0; s < 2; ++s) d.step();
    MPI_Barrier(MPI_COMM_WORLD);
    const std::int64_t halo0 = d.halo_doubles_sent();
    const double h0 = d.halo_seconds();
    const double t0 = MPI_Wtime();
    for (int s = 0; s < steps; ++s) d.step();
    const double mine[2] = {(MPI_Wtime() - t0) / steps, (d.halo_seconds() - h0) / steps};
    double slowest[2] = {0, 0};
    MPI_Reduce(mine, slowest, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    const double bytes = 8.0 * static_cast<double>(d.halo_doubles_sent() - halo0) / steps;
    if (rank == 0) {
      const double nodes = static_cast<double>(c.nx) * c.ny * c.nz;
      std::printf("{\"ranks\": %d, \"weak\": %s, \"lattice\": [%d, %d, %d], \"steps\": %d, \"seconds_per_step\": %.6g, "
                  "\"halo_seconds_per_step\": %.6g, \"mlups\": %.4g, \"halo_bytes_per_rank_step\": %.0f}\n",
                  size, weak ? "true" : "false", c.nx, c.ny, c.nz, steps, slowest[0], slowest[1],
                  nodes / slowest[0] / 1e6, bytes);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_lbm_mpi (rank %d): %s\n", rank, e.what());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  MPI_Finalize();
  return 0;
}
