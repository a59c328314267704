// The MPI capsule solver against LbmCapsuleSolver: a capsule whose kernel crosses the slab
// boundaries (the box centre, where it sits, is a boundary for 2 and 4 ranks) moves and drives
// the fluid as in the serial solver; its checkpoint, written by all ranks, resumes on half the
// ranks and in the serial solver; run_shear with the MPI solver writes the serial run's files.
#include <gtest/gtest.h>

#include <cmath>

#include "bendlab/capsule/shear_units.hpp"
#include "bendlab/capsule/time_series.hpp"
#include "bendlab/flow/shear_run.hpp"
#include "bendlab/membrane/espresso_volume_force.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/parallel/mpi_lbm_capsule_solver.hpp"
#include "lbm/tiny_capsule.hpp"
#include "mpi_test_util.hpp"

using namespace bendlab;
using namespace bendlab::parallel;
using bendlab::test::max_over_ranks;
namespace fs = std::filesystem;

namespace {

using test::membrane;
using test::tiny_options;

// Largest difference of rho and u over all nodes, and of the membrane positions (collective).
double difference(const MpiLbmCapsuleSolver& m, const LbmCapsuleSolver& s) {
  const DistributedLattice& d = m.fluid();
  const lbm::LatticeConfig& c = d.config();
  double e = (m.lattice_positions() - s.lattice_positions()).cwiseAbs().maxCoeff();
  for (int k = 0; k < c.nz; ++k)
    for (int j = d.slab().begin; j < d.slab().begin + d.slab().count; ++j)
      for (int i = 0; i < c.nx; ++i) {
        const std::size_t a = d.local_node(i, j, k), b = s.lattice().index(i, j, k);
        e = std::max(e, std::abs(d.local().density(a) - s.lattice().density(b)));
        e = std::max(e, (d.local().velocity(a) - s.lattice().velocity(b)).cwiseAbs().maxCoeff());
      }
  return max_over_ranks(e, d.comm());
}

}  // namespace

TEST(MpiLbmCapsuleSolver, MatchesTheSerialSolverAcrossSlabBoundaries) {
  const auto o = tiny_options();
  const auto mem = membrane();
  LbmCapsuleSolver serial(mem, o);
  MpiLbmCapsuleSolver mpi(mem, o, MPI_COMM_WORLD);
  EXPECT_EQ(mpi.name(), serial.name());
  EXPECT_EQ(mpi.sample_steps(), serial.sample_steps());
  // The capsule spans the middle layers: with 2 or more ranks its kernel reaches several slabs.
  const double ymin = serial.lattice_positions().col(1).minCoeff(), ymax = serial.lattice_positions().col(1).maxCoeff();
  EXPECT_LT(ymin, -3.0);
  EXPECT_GT(ymax, 3.0);
  for (int s = 0; s < 100; ++s) {
    serial.step();
    mpi.step();
  }
  // The capsule has deformed in the shear: the comparison is not of shapes at rest.
  EXPECT_GT((serial.lattice_positions() - o.radius * mem->reference_positions()).cwiseAbs().maxCoeff(), 1e-3);
  // The velocity sums of nodes whose kernel straddles slabs are taken in the serial order: the
  // capsule and the fluid are the serial ones bit for bit (the acceptance bound is 1e-13).
  EXPECT_EQ(difference(mpi, serial), 0.0);
  EXPECT_EQ(mpi.time(), serial.time());
  EXPECT_EQ(mpi.counters().velocity_evaluations, serial.counters().velocity_evaluations);
}

TEST(MpiLbmCapsuleSolver, CheckpointResumesOnHalfTheRanksAndInTheSerialSolver) {
  const bendlab::test::SharedFolder folder;
  const auto o = tiny_options();
  const auto mem = membrane();
  LbmCapsuleSolver serial(mem, o);
  MpiLbmCapsuleSolver mpi(mem, o, MPI_COMM_WORLD);
  for (int s = 0; s < 51; ++s) {  // odd: the streaming layout
    serial.step();
    mpi.step();
  }
  const SolverState state = mpi.save_state(folder.path(), "00001");
  ASSERT_EQ(state.side_files.size(), 1u);
  EXPECT_TRUE(fs::exists(folder.path() / state.side_files[0]));
  const Points x = mpi.positions();
  const double t = mpi.time();
  // The serial solver resumes from the file the ranks wrote.
  LbmCapsuleSolver serial_resumed(mem, o);
  serial_resumed.restore_state(x, t, mpi.counters(), state.fields, folder.path(), "test");
  for (int s = 0; s < 49; ++s) {
    serial.step();
    serial_resumed.step();
  }
  EXPECT_EQ((serial_resumed.lattice_positions() - serial.lattice_positions()).cwiseAbs().maxCoeff(), 0.0);
  // Half the ranks (4 -> 2, 2 -> 1, ...) resume and continue as the serial run.
  const int half = std::max(1, bendlab::test::world_size() / 2);
  const bendlab::test::SubComm sub(half);
  if (sub.get() != MPI_COMM_NULL) {
    MpiLbmCapsuleSolver resumed(mem, o, sub.get());
    resumed.restore_state(x, t, mpi.counters(), state.fields, folder.path(), "test");
    EXPECT_EQ(resumed.fluid().step_count(), 51);
    for (int s = 0; s < 49; ++s) resumed.step();
    EXPECT_EQ(difference(resumed, serial), 0.0);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(MpiLbmCapsuleSolver, ShearRunWritesTheSerialRunsFilesOnRankZeroOnly) {
  const bendlab::test::SharedFolder folder;
  ShearRunSpec spec;
  spec.solver = "lbm";
  spec.mesh = "mt1:320";
  spec.G = 0.2;
  spec.lattice.radius_lu = 4;
  spec.lattice.box = {2.5, 2.5, 3};
  spec.lattice.sample_every = 0.002;
  spec.t_end = 0.02;
  spec.snapshot_every = 0.01;
  const int rank = bendlab::test::world_rank();
  if (rank == 0) {
    spec.folder = folder.path() / "serial";
    EXPECT_TRUE(run_shear(spec).finished);
  }
  spec.folder = folder.path() / "mpi";
  ShearRunCallbacks cb;
  cb.writes_files = rank == 0;
  cb.make_lbm_solver = [](std::shared_ptr<const MembraneModel> m, const LbmSolverOptions& o) {
    return std::make_unique<MpiLbmCapsuleSolver>(std::move(m), o, MPI_COMM_WORLD);
  };
  const CapsuleRunResult r = run_shear(spec, cb);
  EXPECT_TRUE(r.finished);
  EXPECT_EQ(r.summary.empty(), rank != 0);
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank == 0) {
    const auto a = read_time_series(folder.path() / "serial" / "timeseries.csv");
    const auto b = read_time_series(folder.path() / "mpi" / "timeseries.csv");
    ASSERT_EQ(a.size(), b.size());
    ASSERT_GT(a.size(), 5u);
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(format_time_series_row(a[i]), format_time_series_row(b[i]));
    }
    // The same files, and no temporary ones left behind.
    std::vector<std::string> names_a, names_b;
    for (const auto& e : fs::directory_iterator(folder.path() / "serial")) names_a.push_back(e.path().filename().string());
    for (const auto& e : fs::directory_iterator(folder.path() / "mpi")) names_b.push_back(e.path().filename().string());
    std::sort(names_a.begin(), names_a.end());
    std::sort(names_b.begin(), names_b.end());
    EXPECT_EQ(names_a, names_b);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}
