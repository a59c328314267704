#include "bendlab/flow/shear_simulation.hpp"

#include <fmt/format.h>

#include <cmath>

#include "bendlab/flow/capsule_shape.hpp"
#include "bendlab/flow/volume_correction.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"

namespace bendlab {

namespace {
constexpr double kMu = 1.0, kGamma = 1.0, kR = 1.0;

const ShearParameters& checked(const ShearParameters& p, const BendingMethod* bending) {
  if (!(p.G > 0) || !std::isfinite(p.G)) throw Error(fmt::format("shear: G must be positive, got {}", p.G));
  if (!(p.kappa_b_hat >= 0) || !std::isfinite(p.kappa_b_hat))
    throw Error(fmt::format("shear: kappa_b_hat must be non-negative, got {}", p.kappa_b_hat));
  if (p.kappa_b_hat > 0 && bending == nullptr)
    throw Error("shear: kappa_b_hat > 0 needs a bending method");
  if (!(p.t_end > 0)) throw Error(fmt::format("shear: t_end must be positive, got {}", p.t_end));
  return p;
}

Points centred(const TriMesh& m) {
  Points x = m.positions();
  x.rowwise() -= volume_centroid(m.topology(), x).transpose();
  return x;
}
}  // namespace

ShearSimulation::ShearSimulation(const TriMesh& initial, ShearParameters params, const BendingMethod* bending,
                                 SingleLayerOptions quadrature)
    : topology_(initial.topology_ptr()),
      params_(checked(params, bending)),
      bending_(bending),
      kS_(kMu * kGamma * kR / params.G),
      kB_(params.kappa_b_hat * kR * kR * kS_),
      volume0_(enclosed_volume(initial.topology(), initial.positions())),
      elastic_(initial.topology_ptr(), initial.positions(), kS_),
      single_layer_(initial.topology_ptr(), quadrature),
      x_(centred(initial)) {
  const int n = topology_->num_vertices();
  for (Points* p : {&xb_, &force_, &fbend_, &density_, &u_, &grad_}) p->resize(n, 3);
}

void ShearSimulation::restart(const Points& positions, double time, double dt_next) {
  if (positions.rows() != topology_->num_vertices())
    throw Error(fmt::format("shear restart: {} positions for {} vertices", positions.rows(), topology_->num_vertices()));
  if (!positions.allFinite()) throw Error("shear restart: positions are not finite");
  if (!std::isfinite(time) || time < 0) throw Error(fmt::format("shear restart: invalid time {}", time));
  x_ = positions;
  t_ = time;
  dt_next_ = dt_next > 0 ? dt_next : 0;
}

void ShearSimulation::velocity(const Points& x, Points& u) {
  const Topology& t = *topology_;
  elastic_.forces(x, force_);
  if (bending_ != nullptr && kB_ > 0) {
    bending_->forces(t, x, kB_, fbend_);
    force_ += fbend_;
  }
  const MeshGeometry geometry = MeshGeometry::compute(t, x);
  density_ = force_.array().colwise() / geometry.mixed_area.array();  // eq. (14)
  single_layer_.velocity(x, density_, kMu, u);
  u.col(0) += kGamma * x.col(2);  // u_inf = gamma z e_x
  volume_gradient(t, x, grad_);
  project_zero_flux(grad_, u);
  ++evaluations_;
}

ShearSample ShearSimulation::sample(const Points& x, double time, double dt, std::int64_t step) const {
  ShearSample s;
  s.step = step;
  s.time = time;
  s.dt = dt;
  s.positions = &x;
  const CapsuleShape shape = capsule_shape(*topology_, x);
  s.D = shape.D;
  s.theta = shape.theta;
  s.volume = shape.volume;
  s.area = surface_area(*topology_, x);
  s.E_elastic = elastic_.energy(x);
  if (bending_ != nullptr) s.E_bend = bending_->energy(*topology_, x, kB_);
  return s;
}

CashKarpStats ShearSimulation::run(const Callback& callback) {
  CashKarpOptions options;
  options.rtol = params_.rtol;
  options.atol = params_.atol;
  CashKarp integrator(options);
  const int n = topology_->num_vertices();
  if (!(params_.t_end > t_)) {
    CashKarpStats st;
    st.t = t_;
    st.dt_next = dt_next_;
    return st;
  }
  // The state vector is the row-major N x 3 position array, flattened.
  Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(x_.data(), 3 * n);
  auto rhs = [&](double, const Eigen::VectorXd& state, Eigen::VectorXd& dydt) {
    xb_ = Eigen::Map<const Points>(state.data(), n, 3);
    velocity(xb_, u_);
    dydt = Eigen::Map<const Eigen::VectorXd>(u_.data(), 3 * n);
  };
  std::int64_t steps = 0;
  auto on_accept = [&](double t, double dt, Eigen::VectorXd& state) {
    Eigen::Map<Points> xs(state.data(), n, 3);
    x_ = xs;
    rescale_to_volume(*topology_, x_, volume0_);
    xs = x_;
    t_ = t;
    dt_next_ = integrator.proposed_step();
    ++steps;
    if (!callback) return true;
    ShearSample s = sample(x_, t, dt, steps);
    s.dt_next = dt_next_;
    return callback(s);
  };
  const CashKarpStats st = integrator.integrate(rhs, t_, params_.t_end, y, dt_next_, on_accept);
  dt_next_ = st.dt_next;
  return st;
}

}  // namespace bendlab
