// Timing of many cells over MPI ranks (parallel/mpi_suspension.hpp) on the case of HemoCell's
// pipeflow example (bench/pipeflow_case.hpp: a 25 um tube, 50 um long, dx = 0.5 um, 36 red blood
// cells of 1280 triangles, Method C, and 6 small stiff cells; every force every step), against the
// serial suspension on rank 0 alone. Run under mpirun:
//   mpirun -np P bench_suspension_mpi STEPS [serial]
// Takes 2 warm-up steps, then STEPS timed steps; the slowest rank's time counts. With "serial",
// rank 0 first times the serial LbmSuspension on the same case. Prints one JSON line on rank 0:
// ranks, threads per rank, cells, seconds per step, steps per second (and the serial ones).
#include <mpi.h>
#include <omp.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "bendlab/parallel/mpi_suspension.hpp"
#include "pipeflow_case.hpp"

using namespace bendlab;

namespace {
template <class S>
double seconds_per_step(S& s, int steps, MPI_Comm comm) {
  for (int k = 0; k < 2; ++k) s.step();
  MPI_Barrier(comm);
  const double t0 = MPI_Wtime();
  for (int k = 0; k < steps; ++k) s.step();
  const double mine = (MPI_Wtime() - t0) / steps;
  double slowest = 0;
  MPI_Allreduce(&mine, &slowest, 1, MPI_DOUBLE, MPI_MAX, comm);
  return slowest;
}
}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (argc < 2) {
    if (rank == 0) std::fprintf(stderr, "usage: bench_suspension_mpi STEPS [serial]\n");
    MPI_Finalize();
    return 2;
  }
  const int steps = std::atoi(argv[1]);
  const bool serial = argc > 2 && std::string(argv[2]) == "serial";
  try {
    double serial_seconds = 0;
    if (serial && rank == 0) {
      lbm::LbmSuspension s(bench::pipeflow_options());
      bench::add_pipeflow_cells(s, 0, [&] { return s.positions(); });
      serial_seconds = seconds_per_step(s, steps, MPI_COMM_SELF);
    }
    parallel::MpiSuspension d(bench::pipeflow_options(), MPI_COMM_WORLD);
    bench::add_pipeflow_cells(d, 0, [&] { return d.gather_positions(); });
    const double seconds = seconds_per_step(d, steps, MPI_COMM_WORLD);
    if (rank == 0) {
      std::printf("{\"ranks\": %d, \"threads\": %d, \"cells\": %d, \"steps\": %d, \"seconds_per_step\": %.6g, "
                  "\"steps_per_second\": %.4g",
                  size, omp_get_max_threads(), d.num_cells(), steps, seconds, 1.0 / seconds);
      if (serial) std::printf(", \"serial_seconds_per_step\": %.6g, \"serial_steps_per_second\": %.4g", serial_seconds,
                              1.0 / serial_seconds);
      std::printf("}\n");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_suspension_mpi (rank %d): %s\n", rank, e.what());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  MPI_Finalize();
  return 0;
}
