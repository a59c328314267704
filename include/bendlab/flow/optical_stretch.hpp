#pragma once
// Optical-tweezers stretching of one cell (Mills et al. 2004, Mech. Chem. Biosyst. 1:169; the check
// of Dao et al. 2003, Fedosov et al. 2010, HemoCell and Mirheo; shared/spec/CELLS_IN_CHANNELS.md
// section 5): a total force +F e_x spread evenly over the `fraction` of the vertices with the largest
// x and -F e_x over as many with the smallest x, the cell in equilibrium under them.
//
// The cell is a CellKind (flow/cell_kind.hpp: the red blood cell of eq. (15) at R = 3.91 um with
// the flow runs' membrane) in um and pN (physical_membrane()). Equilibrium is found by FIRE (the
// fast inertial relaxation engine, Bitzek, Koskinen, Gaehler, Moseler & Gumbsch 2006, Phys. Rev.
// Lett. 97:170201) on the total nodal force R = F_membrane + F_applied, which needs forces only
// (Method C's force is no energy's gradient): it stops when max_i |R_i| falls below the tolerance,
// or fails after max_iterations. Each force starts from the previous force's equilibrium.
// docs/conventions.md §7 states the measures and defaults.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bendlab/core/types.hpp"
#include "bendlab/flow/cell_kind.hpp"
#include "bendlab/membrane/membrane_model.hpp"

namespace bendlab {

/// FIRE's parameters (Bitzek et al. 2006, their recommended values) and the step bound.
struct FireParameters {
  int n_min = 5;              ///< steps with P > 0 before the time step may grow
  double f_inc = 1.1;         ///< time step growth
  double f_dec = 0.5;         ///< time step cut when P <= 0
  double alpha_start = 0.1;   ///< initial mixing of the velocity towards the force
  double f_alpha = 0.99;      ///< mixing decay
  /// dt_max = dt_max_factor / sqrt(lambda), lambda the largest eigenvalue of the force's Jacobian
  /// (unit masses) estimated by power iteration at the start of every force: semi-implicit Euler
  /// is stable below 2 / sqrt(lambda), so 1 leaves a factor two.
  double dt_max_factor = 1.0;
  double dt_start_fraction = 0.1;  ///< dt at the start = this fraction of dt_max (Bitzek: dt_max = 10 dt_MD)
  double max_step_edges = 0.1;     ///< no vertex moves more than this fraction of the mean edge per step
};

/// How the equilibrium is sought. FIRE moves the vertices as masses (inertial), which converges for
/// a force that is an energy's gradient or nearly so (A, B, J, S, C, E): its Jacobian is about
/// symmetric, its eigenvalues -omega^2 real. A force whose Jacobian is far from symmetric (M, and less
/// so D and ED: docs/results/bending_stability.md) has complex eigenvalues mu = -a + ib, and the undamped motion
/// x'' = mu x then grows like exp(Re sqrt(mu) t), Re sqrt(mu) > 0 for any b != 0 (flutter): the
/// masses circle the equilibrium instead of settling. Overdamped relaxation, dx/dt = R (the motion
/// of a cell in Stokes flow, with unit mobility), decays wherever every eigenvalue has a negative
/// real part, the condition a flow run needs; it is slower (its steps scale with the ratio of the
/// stiffest mode to the softest), so Anderson mixing of its last steps accelerates it.
/// Auto (the default) picks Overdamped for M and FIRE for the rest (and for no bending).
enum class StretchRelaxation { Auto, Fire, Overdamped };

/// The relaxation Auto stands for with this bending method ("none" for no bending).
StretchRelaxation default_relaxation(const std::string& method);
std::string to_string(StretchRelaxation r);

struct StretchSpec {
  CellKindSpec cell;                ///< shape, mesh, law, moduli and method (the flow's red blood cell)
  std::vector<double> forces_pN;    ///< total force F at each end, pN, in the order run
  double fraction = 0.02;           ///< fraction of the vertices pulled at each end
  double tolerance_pN = 1e-4;       ///< max nodal residual |F_membrane + F_applied| at equilibrium, pN
  long max_iterations = 20000;      ///< relaxation steps per force before failing
  StretchRelaxation relaxation = StretchRelaxation::Auto;
  FireParameters fire;
  nlohmann::json to_json() const;
};

/// Throws bendlab::Error, one line naming the option (--forces, --fraction, --tolerance,
/// --max-iterations, and check_cell_kind's), for a force that is negative or not finite, no force,
/// a fraction not in (0, 0.5], a non-positive or non-finite tolerance or iteration count.
void check_stretch(const StretchSpec& spec);

/// The number of vertices pulled at each end: round(fraction N). Throws bendlab::Error (naming
/// --fraction) when that is 0, or when the two ends would share a vertex (2 n > N).
int pulled_vertex_count(double fraction, int num_vertices);

/// Measures of one shape (docs/conventions.md §7).
struct StretchMeasures {
  double axial_um = 0;        ///< max x - min x over the vertices
  double transverse_um = 0;   ///< the largest extent across x: the largest distance between two
                              ///< vertices projected onto the y-z plane (the largest width over
                              ///< all directions in that plane)
  double extent_y_um = 0, extent_z_um = 0;
  double area_um2 = 0, volume_um3 = 0;
};
StretchMeasures stretch_measures(const Topology& topology, const Points& x);

/// One equilibrium.
struct StretchPoint {
  double force_pN = 0;
  bool converged = false;
  long iterations = 0;          ///< FIRE steps taken (0: the start already met the tolerance)
  double residual_pN = 0;       ///< max_i |F_membrane,i + F_applied,i| at the end
  double membrane_force_sum_pN = 0;  ///< |sum_i F_membrane,i|
  double applied_force_sum_pN = 0;   ///< |sum_i F_applied,i|
  double lambda_max = 0;        ///< the power iteration's estimate (pN/um per unit mass)
  int restarts = 0;             ///< FIRE restarts with a halved step after a divergence
  std::string failure;          ///< why it did not converge (empty when it did)
  StretchMeasures measures;
  double area_change = 0, volume_change = 0;  ///< A / A0 - 1, V / V0 - 1 against the reference
  nlohmann::json to_json() const;
};

class OpticalStretch {
 public:
  /// Checks spec (check_stretch) and builds the cell, its membrane and the two pulled sets, chosen
  /// on the reference shape (ties in x broken by the lower vertex index).
  explicit OpticalStretch(StretchSpec spec);

  /// Relaxes the current shape under force_pN (the total at each end) and returns the
  /// equilibrium; the shape stays there for the next call. A relaxation that diverges (a force
  /// that is not finite, a folded mesh, a residual a thousand times its start) starts again from the
  /// first shape with half the time step, up to 8 times; a point that did not converge says why in
  /// `failure` and keeps its last shape (its first after a divergence). `progress` (may be empty) gets a line now and then on long relaxations.
  StretchPoint equilibrate(double force_pN, const std::function<void(const std::string&)>& progress = {});

  /// The applied nodal forces for a total force F (N x 3, pN): +F/n e_x on the right set,
  /// -F/n e_x on the left one, zero elsewhere.
  Points applied_forces(double force_pN) const;

  const StretchSpec& spec() const { return spec_; }
  const CellKind& cell() const { return kind_; }
  const MembraneModel& membrane() const { return *membrane_; }
  const Points& positions() const { return x_; }
  const Points& membrane_force() const { return membrane_force_; }  ///< at positions(), after equilibrate()
  const std::vector<int>& right_vertices() const { return right_; }
  const std::vector<int>& left_vertices() const { return left_; }
  const StretchMeasures& reference_measures() const { return reference_measures_; }

 private:
  double estimate_lambda(const Points& applied);

  StretchSpec spec_;
  CellKind kind_;
  std::shared_ptr<const MembraneModel> membrane_;
  std::vector<int> right_, left_;
  Points x_, membrane_force_;
  StretchMeasures reference_measures_;
  double mean_edge_um_ = 0;
};

}  // namespace bendlab
