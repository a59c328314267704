#pragma once
// D3Q19 lattice Boltzmann fluid for the immersed-boundary capsule solver (paper section 4.3.2;
// technical note shared/spec/LBM_IBM.md sections 1-2). Lattice units dx = dt = 1, rho0 = 1.
//
// Collision: BGK with Guo forcing,
//   f_i* = f_i - (f_i - f_i^eq(rho, u)) / tau + (1 - 1/(2 tau)) w_i [3 (c_i - u) + 9 (c_i.u) c_i].F,
// which is ESPResSo's MRT scheme exactly at tau = 1 (default bulk and ghost relaxation), and for
// tau != 1 the regularised form that equals ESPResSo's MRT: from rho, j = sum f c and
// Pi = sum f c c, relax the traceless part of Pi - Pi^eq by 1 - 1/tau and drop its trace (bulk
// mode fully relaxed), add the forcing (1 - 1/(2 tau)) traceless(uF + Fu) + (1/3)(u.F) I and
// j* = j + F, and rebuild f_i = w_i [rho + 3 c_i.j* + 4.5 (Pi* - rho/3 I) : (c_i c_i - I/3)].
// The velocity is always u = (sum_i f_i c_i + F/2) / rho (in f^eq, in output, for the IBM).
//
// Geometry: nx x ny x nz nodes, node (i, j, k) at the physical position
// (i + 1/2 - nx/2, j + 1/2 - ny/2, k + 1/2 - nz/2): the box is centred on the origin, where the
// capsule sits (docs/conventions.md). x and y are periodic. With walls, flat walls lie halfway between
// the outermost nodes and the (absent) next ones, at z = -nz/2 (moving with -v e_x) and z = +nz/2
// (moving with +v e_x): link bounce-back with wall velocity (Ladd), pull form
//   f_i(x, t+1) = f_ibar*(x, t) + 6 w_i rho0 c_i.u_w   where x - c_i lies in the wall,
// so the shear flow is u = gamma z e_x with gamma = 2 v / nz. Without walls z is periodic too.
//
// Channels and tubes (shared/spec/CELLS_IN_CHANNELS.md section 1). A uniform body force density g
// (LatticeConfig::body_force, Guo forcing like the force field) drives the flow along x between
// resting walls: the flat walls above with v = 0 (a slit channel), or a cross-section
// (section_walls.hpp) whose solid rows along x the kernel skips and whose links into the solid are
// bounced back for the whole row. Those links are then corrected to the wall's true position by
// the linear interpolated bounce-back of Bouzidi, Firdaouss & Lallemand (2001): for a link from the
// fluid node x_f along c_q meeting the wall at the fraction q of its length, the population
// returning along -c_q is
//   q <  1/2:  2 q f*_q(x_f) + (1 - 2 q) f*_q(x_f - c_q)
//   q >= 1/2:  f*_q(x_f) / (2 q) + (2 q - 1) / (2 q) f*_qbar(x_f)
// (f* post-collision; plain bounce-back where x_f - c_q is solid too). The interpolation does not
// conserve mass, so the node's rest population takes back the difference to the plain bounce-back
// (mass exactly conserved, momentum untouched). In the AA layout each of
// these values sits in known slots once a step is complete, so a pass over the wall links after
// every step rewrites the returning populations (apply_interpolated_bounce_back): the second
// order of the wall survives without touching the kernel's rows.
// Collision::TRT (two relaxation times, Ginzburg) relaxes the even part of each pair of opposite
// populations with 1/tau and the odd part with omega_- from the magic parameter
// Lambda = (tau - 1/2)(1/omega_- - 1/2) (3/16 by default), which puts a halfway bounce-back wall
// of a Poiseuille flow exactly halfway at any tau.
//
// Memory layout: structure of arrays (population i of every node contiguous, x fastest) and a
// single lattice updated with the AA pattern (Bailey et al. 2009): an even step reads the 19
// populations of a node and writes the post-collision values back to the same node in the
// opposite slots; an odd step reads from the neighbours (slot ibar of x - c_i), collides and
// writes to the neighbours (slot i of x + c_i). Every node reads and writes the same 19 locations
// in both steps, so each update moves 19 + 19 doubles plus the 3 force components: 328 bytes per
// node update (no write-allocate traffic, no second lattice). Which slot holds which population
// therefore depends on the parity of the step; populations() hides it.
// The 19 slots (and the 3 force components) lie slot_stride() doubles apart, not num_nodes():
// at power-of-two lattice sizes (128^3) arrays a power of two apart map the 41 streams of a row
// onto the same cache sets and 4 KiB aliases, so each slot is padded to an odd number of cache
// lines past a multiple of 4 KiB (slot_stride).
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "bendlab/core/aligned_allocator.hpp"
#include "bendlab/core/types.hpp"
#include "bendlab/flow/lbm/d3q19.hpp"
#include "bendlab/flow/lbm/section_walls.hpp"

namespace bendlab::lbm {

enum class Collision {
  Auto,         ///< BGK at tau == 1, Regularized otherwise
  BGK,          ///< BGK + Guo at any tau (ESPResSo's scheme only at tau = 1)
  Regularized,  ///< ESPResSo's MRT with default bulk/ghost relaxation, for any tau
  TRT,          ///< two relaxation times with the magic parameter LatticeConfig::trt_magic, + Guo
};

struct LatticeConfig {
  int nx = 0, ny = 0, nz = 0;
  double tau = 1.0;              ///< relaxation time; viscosity nu = (tau - 1/2) / 3
  bool walls = true;             ///< walls at z = -+nz/2; false: fully periodic box
  double wall_velocity = 0.0;    ///< v: the top wall moves with +v e_x, the bottom one with -v e_x
  Collision collision = Collision::Auto;
  /// Pads the slots of the store (slot_stride()); false puts them num_nodes() apart, the plain
  /// layout kept as the reference the padded one is tested and benchmarked against.
  bool pad_slots = true;
  /// Uniform body force density g (force per node), added to the force field in the collision
  /// and in velocity(): it drives channel and tube flows without touching the sparse field the
  /// immersed boundary writes.
  Vec3 body_force = Vec3::Zero();
  /// Lambda of Collision::TRT; 3/16 puts a plain bounce-back wall exactly halfway at any tau.
  double trt_magic = 3.0 / 16.0;
  /// Walls parallel to x (a tube); null: none. Rows whose centre it calls solid are not stepped.
  std::shared_ptr<const SectionWalls> section;
  /// false: the section's links keep the plain bounce-back (a staircase wall), the first-order
  /// reference the interpolated one is measured against.
  bool interpolated_walls = true;
  /// true: the interpolated bounce-back by its plain per-node loop, the reference the fast pass
  /// (branches hoisted per link, the row's two ends apart) must equal bit for bit (tests).
  bool reference_wall_pass = false;
  /// true: layers j = 0 and ny - 1 are ghost copies of a neighbouring subdomain's layers
  /// (parallel/distributed_lattice.hpp), never stepped: the section's wall links and its check
  /// that the section closes inside the box (across the y wrap) then cover the layers between.
  bool ghost_y_layers = false;
};

class Lattice {
 public:
  /// Validates the configuration (positive sizes, tau > 1/2, finite wall velocity) and starts at
  /// rest with rho = 1 and a zero force field.
  explicit Lattice(const LatticeConfig& config);

  const LatticeConfig& config() const { return config_; }
  int nx() const { return config_.nx; }
  int ny() const { return config_.ny; }
  int nz() const { return config_.nz; }
  std::size_t num_nodes() const { return n_; }
  double viscosity() const { return (config_.tau - 0.5) / 3.0; }
  /// gamma = 2 v / nz with walls, 0 without.
  double shear_rate() const;
  /// The collision actually used (Auto resolved).
  Collision collision() const { return collision_; }
  /// Completed steps (its parity tells the AA layout of the populations).
  std::int64_t step_count() const { return step_; }

  std::size_t index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(config_.nx) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(config_.ny) * static_cast<std::size_t>(k));
  }
  /// Whether node (j, k)'s row along x lies in the solid of config().section (never without one).
  bool solid_row(int j, int k) const { return !solid_rows_.empty() && solid_rows_[static_cast<std::size_t>(j) + static_cast<std::size_t>(config_.ny) * static_cast<std::size_t>(k)] != 0; }
  bool is_solid(std::size_t node) const;
  /// Nodes in the fluid (num_nodes() less the solid rows).
  std::size_t num_fluid_nodes() const { return fluid_nodes_; }
  /// Links from a fluid row into a solid row (each counted once per row, not per node).
  std::size_t num_wall_links() const { return wall_links_.size(); }
  /// (i, j, k) of a node index.
  std::array<int, 3> coordinates(std::size_t node) const;
  /// Physical position of node (i, j, k) (box centred on the origin).
  Vec3 position(int i, int j, int k) const;

  /// Sets every node to f^eq(rho(x), u(x)) (plus, if `stress` is given, the non-equilibrium part
  /// -3 tau w_i rho c_i c_i : S(x) of the velocity gradient S = grad u, S(x)(a, b) = d u_b / d x_a),
  /// evaluated at the physical node positions; resets the step count to 0.
  void initialise(const std::function<Vec3(const Vec3&)>& velocity,
                  const std::function<double(const Vec3&)>& density = nullptr,
                  const std::function<Mat3(const Vec3&)>& stress = nullptr);
  /// The exact linear shear flow u = gamma z e_x of the walls, with its non-equilibrium stress
  /// (a steady state of the scheme); step count 0.
  void initialise_shear_flow();

  /// The force density field (force per node) applied in the next step, Guo forcing. It is not
  /// reset by step(): velocity() uses it for the F/2 correction after the step (ESPResSo's order),
  /// and the caller clears it before spreading new forces (only the nodes written since the last
  /// clear, when they are few).
  void clear_force();
  void add_force(std::size_t node, const Vec3& F) {
    double* f = force_.data();
    f[node] += F.x();
    f[stride_ + node] += F.y();
    f[2 * stride_ + node] += F.z();
    note_forced(node);
  }
  void set_uniform_force(const Vec3& F);
  /// The force field to add to directly, component d of node n at [d * slot_stride() + n], for
  /// writers that cover most nodes from several threads (the immersed boundary's spreading); the
  /// next clear_force then clears the whole field.
  double* force_field_for_writing() {
    force_everywhere_ = true;
    forced_.clear();
    forced_runs_.clear();
    return force_.data();
  }
  /// `count` consecutive nodes of one x-row from node `first`.
  struct NodeRun {
    std::size_t first;
    int count;
  };
  /// The same for a writer that adds to the nodes of `within` only: the next clear_force clears
  /// those runs (all of the field once the runs written since the last clear cover half of it).
  double* force_field_for_writing(const std::vector<NodeRun>& within);
  Vec3 force(std::size_t node) const {
    const double* f = force_.data();
    return {f[node], f[stride_ + node], f[2 * stride_ + node]};
  }
  /// Component d (0, 1, 2) of the force field, num_nodes() values.
  const double* force_data(int d) const { return force_.data() + d * stride_; }

  /// One step: collide with the force field (Guo), stream, bounce back at the walls. OpenMP over
  /// the (y, z) rows.
  void step();
  /// step(), which also computes, for the runs (ascending, each in one x-row) whose populations
  /// are final before the step ends, velocities_of_run(run.first, run.count, u + 3 * run.first) as
  /// it would after the step, bit for bit, and sets done[k] to 1 for those (0 for the others).
  /// A thread computes a run's velocities once it has stepped every row the run's row reads from,
  /// while those rows are still in its cache; without that, the immersed boundary's gather read
  /// them back from memory after the step, at about the cost of the step itself. Left for the
  /// caller (done[k] = 0): rows whose neighbours another thread steps, and rows next to a wall
  /// link, which the wall pass changes after the collision.
  void step_gathering(const std::vector<NodeRun>& runs, double* u, std::vector<std::uint8_t>& done);
  /// One step of the layers j0 <= j < j1 only; the others keep their populations. For a
  /// subdomain whose layers j0 - 1 and j1 are ghost copies of a neighbour's (kept by the caller,
  /// parallel/distributed_lattice.hpp): a stepped layer then never wraps around in y.
  /// step() is step_layers(0, ny()).
  void step_layers(int j0, int j1);
  /// step_layers in its two parts, for a subdomain whose ghost layers must be exchanged between
  /// them: collide and stream the layers (the step count advances), then correct the section's
  /// wall links of those layers to the wall's position (the interpolated bounce-back, which reads
  /// the populations that stream in from the ghost layers). step_layers is the one, then the other.
  void collide_stream_layers(int j0, int j1);
  void correct_section_walls(int j0, int j1);
  void run(std::int64_t steps) {
    for (std::int64_t s = 0; s < steps; ++s) step();
  }

  /// The 19 post-stream populations of a node at the current step (layout-independent). After an
  /// odd step they sit at the neighbours; a table of each row's source rows finds them.
  void populations(std::size_t node, double f[kQ]) const;
  /// The same from the node's coordinates, wall by wall: the reference populations() is tested
  /// against, bit for bit.
  void populations_reference(std::size_t node, double f[kQ]) const;
  /// rho = sum f; 1 at a node in the solid of the cross-section, which holds no fluid (its slots
  /// serve the bounce-back of the fluid around it, and after an odd step populations() there
  /// reads what its fluid neighbours pushed, not a state of the node).
  double density(std::size_t node) const;
  /// u = (sum f c + F/2) / rho with the current force field (and the body force); zero at a node
  /// in the solid of the cross-section (the resting wall, which the immersed boundary then sees).
  Vec3 velocity(std::size_t node) const;
  /// velocity() of the `count` consecutive nodes node, node + 1, ... of one x-row (all in the row
  /// of `node`), bit for bit, written to u as x, y, z per node. A population slot is read for the
  /// whole run at once, so the loop over the run vectorises: the gather of the immersed boundary.
  void velocities_of_run(std::size_t node, int count, double* u) const;
  /// Sum of rho, and of sum f c (without F/2), over all fluid nodes.
  double total_mass() const;
  Vec3 total_momentum() const;

  /// The raw populations, kQ * num_nodes() doubles, slot-major without padding, in the AA layout
  /// of step_count() (a copy, for checkpoints).
  std::vector<double> raw_populations() const;
  /// Distance in doubles between two slots of the store (num_nodes() or more, see the layout above).
  std::size_t slot_stride() const { return stride_; }
  /// The store itself: slot q of node n at raw_data()[q * slot_stride() + n] (for the halo
  /// exchange and the checkpoint of a subdomain, parallel/distributed_lattice.hpp).
  double* raw_data() { return f_.data(); }
  const double* raw_data() const { return f_.data(); }
  /// Replaces the populations (as raw_populations() gives them) and the step count (sizes must
  /// match; for checkpoints).
  void restore_raw(const std::vector<double>& populations, std::int64_t step);

 private:
  // step_gathering's part of the step: the runs, the velocities and the flags.
  struct Gather {
    const std::vector<NodeRun>* runs;
    double* u;
    std::uint8_t* done;
  };
  template <class Coll>
  void step_with(const Coll& coll, int j0, int j1, const Gather* gather = nullptr);
  void collide_stream_layers(int j0, int j1, const Gather* gather);
  template <class Args, class Coll>
  void gather_while_stepping(const Args& a, int r0, int r1, const Coll& coll, const Gather& g) const;
  /// velocities_of_run after `steps` steps (the parity of the AA layout), whatever step_ is.
  void velocities_of_run_after(std::size_t node, int count, double* u, std::int64_t steps) const;
  /// gather_lo_, gather_hi_ (below), from pull_rows_ and wall_links_.
  void build_gather_rows();
  void build_section();
  /// pull_rows_ (below).
  void build_pull_rows();
  /// The interpolated bounce-back pass after a step (header comment); `after_odd` tells where the
  /// step left its populations.
  void apply_interpolated_bounce_back(bool after_odd, int j0, int j1);
  void interpolated_bounce_back_reference(bool after_odd, int j0, int j1);

  LatticeConfig config_;
  Collision collision_;
  std::size_t n_;
  std::size_t stride_;
  std::int64_t step_ = 0;
  AlignedDoubles f_;      // kQ slots of stride_ doubles
  AlignedDoubles force_;  // 3 components of stride_ doubles
  // The nodes add_force wrote since the last clear_force, so that clearing the few nodes an
  // immersed boundary touches does not sweep the whole field every step; everywhere once the
  // list would exceed num_nodes() / 8 or after set_uniform_force.
  std::vector<std::size_t> forced_;
  std::vector<NodeRun> forced_runs_;  // and the runs given to force_field_for_writing
  std::size_t forced_run_nodes_ = 0;  // their nodes
  bool force_everywhere_ = false;
  // The cross-section: solid flag per row (j + ny k), empty without one, and the links of fluid
  // rows into solid rows with the wall fraction q and whether the row behind (x_f - c_q) is fluid.
  struct WallLink {
    int j, k, q;
    double fraction;
    bool back_fluid;
    int jb, kb;  // the row of x_f - c_q (periodic wrap)
  };
  std::vector<std::uint8_t> solid_rows_;
  // Per row (j + ny k) and direction q, where f_q of its nodes comes from after an odd step: the
  // source row (j - c_qy, k - c_qz wrapped), or one of the codes below (populations()).
  static constexpr std::int32_t kPullSolid = -1, kPullBottomWall = -2, kPullTopWall = -3;
  std::vector<std::int32_t> pull_rows_;
  // Per row: the lowest and highest row whose stepping writes populations that the row's velocity
  // reads (the row itself and its source rows); a row beside a wall link has hi = INT32_MAX, for
  // the wall pass changes it after the collision (step_gathering).
  std::vector<std::int32_t> gather_lo_, gather_hi_;
  std::vector<WallLink> wall_links_;
  std::vector<double> wall_buffer_;
  std::size_t fluid_nodes_ = 0;
  void note_forced(std::size_t node) {
    if (force_everywhere_) return;
    if (forced_.size() >= n_ / 8) {
      force_everywhere_ = true;
      forced_.clear();
      return;
    }
    forced_.push_back(node);
  }
};

}  // namespace bendlab::lbm
