#pragma once
// The recorder of a suspension run (capsule/run_recorder.hpp; shared/spec/CELLS_IN_CHANNELS.md
// section 3; docs/conventions.md §6): what a blood-flow code is judged by, in physical units.
//
//   timeseries.csv  one row per reported step:
//                   t_s, dt_s, flow_rate_um3_s, mean_velocity_um_s, apparent_viscosity,
//                   tube_hematocrit, discharge_hematocrit, cell_free_layer_um
//     Q             the flow rate: the fluid nodes' u_x summed and divided by the period
//                   (the volume flux through a cross-section, averaged along x);
//     v = Q / A     A the section's area (pi D^2 / 4, or H W);
//     eta_app / eta = Q0 / Q, Q0 the flow rate of the cell-free flow on the same lattice with
//                   the same driving (flow_run.hpp relaxes it before the run);
//     H_T, H_D, the cell-free layer: suspension/flow_measures.hpp (slices of slice_width_um).
//     In the shear box (a lattice whose walls move) the net flux is zero: eta_app / eta is the
//     walls' shear stress over eta gamma (flow/lbm/wall_stress.hpp), the suspension's relative
//     viscosity, and H_D is not defined (NaN in the file, null in the summary).
//   cells.csv       one row per cell per reported step: t_s, cell, the centroid (um), its
//                   velocity along x (um/s, the mean of its vertices'), the Taylor deformation D of
//                   its equivalent ellipsoid, and the angle (degrees, 0..90) between its axis of
//                   symmetry (the shortest axis) and the flow.
//   fluid_NNNNN.vtk with each snapshot: the fluid's velocity and density on the plane y = 0
//                   through the axis (tube) or the middle (channel), as VTK structured points
//                   in um and um/s (ParaView reads it; the first of the plane's node rows
//                   nearest y = 0).
//   profiles.csv    at the end: across the section (r in a tube, z in a channel), in bins of one
//                   dx, the steady window's mean fluid velocity and local hematocrit (the row
//                   occupancy of the lines through the lattice nodes), and the nodes per bin.
//
// Summary (summary.json): apparent_viscosity, tube_hematocrit, discharge_hematocrit,
// cell_free_layer_um and mean_velocity_um_s, each {"mean", "standard_error", "rows"} over the
// steady window [steady_from t_end, t_end], read back from timeseries.csv as written (so a
// resumed run's summary equals the uninterrupted one's). The standard error is that of ten
// batch means (correlated rows: a plain standard error would be too small), or of the rows
// themselves when fewer than 20 lie in the window.
//
// Checkpoint state: {"profiles": the running sums of the profiles at full precision}.
#include <optional>
#include <vector>

#include "bendlab/capsule/run_recorder.hpp"
#include "bendlab/core/row_file.hpp"
#include "bendlab/flow/lbm/lattice.hpp"
#include "bendlab/flow/suspension_solver.hpp"
#include "bendlab/suspension/vessel.hpp"

namespace bendlab {

struct SuspensionRecorderOptions {
  Vessel vessel_um = Vessel::box(1, 1, 1);  ///< the vessel in um
  double reference_flow_rate = 0;           ///< Q0, um^3/s (positive; unused in the shear box)
  double slice_width_um = 1;                ///< the cell-free layer's slices along x
  double steady_from = 0.5;                 ///< the steady window starts at steady_from t_end
};

/// Q of a lattice in um^3/s: the lines' sums added in index order and divided by the period, as
/// the recorder's flow rate.
double lattice_flow_rate(const lbm::Lattice& lattice, double dx_um, double dt_seconds);

/// Mean and standard error of `values` (batch means as above); NaN for no values.
struct MeanWithError {
  double mean = 0, standard_error = 0;
  std::int64_t rows = 0;
};
MeanWithError mean_with_error(const std::vector<double>& values);

class SuspensionRecorder final : public RunRecorder {
 public:
  /// Keeps `solver` by reference. Throws bendlab::Error for a non-positive Q0 (outside the shear
  /// box), slice width or a
  /// steady_from outside [0, 1).
  SuspensionRecorder(const SuspensionSolver& solver, SuspensionRecorderOptions options);

  bool is_output(const std::string& name) const override;
  void start(const std::filesystem::path& folder, double t_end, bool writes_files) override;
  double check_resume(const std::filesystem::path& folder, const CapsuleCheckpoint& saved, double t_end,
                      bool writes_files, const std::string& source) override;
  void resume(const std::filesystem::path& folder, const CapsuleCheckpoint& saved, double t_end, bool writes_files,
              const std::function<void(const std::string&)>& note) override;
  void record(const AcceptedStep& step) override;
  /// fluid_<tag>.vtk (the layer is read on every process: the solver's read may be collective).
  void snapshot(const std::filesystem::path& folder, const std::string& tag) override;
  /// H_D, eta_app / eta and the cell-free layer of the last row.
  ProgressMeasures progress() const override;
  nlohmann::json state() const override;
  nlohmann::json summary(const std::filesystem::path& folder, double t_end, const Points& positions) const override;

  /// The last row of timeseries.csv (its columns as above).
  const NumberRow& last_row() const { return last_; }
  static const char* series_header();
  static const char* cells_header();

 private:
  int num_cells() const;

  const SuspensionSolver& solver_;
  bool writes_files_ = false;
  SuspensionRecorderOptions options_;
  bool shear_box_ = false;  // the lattice's walls move: viscosity from their stress
  double t_end_ = 0;
  std::optional<RowFile> series_, cells_;
  NumberRow last_;
  // The profiles: per bin, its lines of fluid nodes along x, and the running sums over the
  // window's samples.
  std::vector<int> bin_of_line_;  // per (j, k) line of the lattice; -1 outside the fluid
  std::vector<char> fluid_line_;  // per (j, k) line: not in the wall's solid rows
  std::vector<double> bin_lines_, velocity_sum_, hematocrit_sum_;
  std::int64_t profile_samples_ = 0;
  std::optional<nlohmann::json> saved_profiles_;
};

}  // namespace bendlab
