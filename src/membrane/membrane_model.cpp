#include "bendlab/membrane/membrane_model.hpp"

#include <fmt/format.h>

#include <cmath>

#include "bendlab/core/finite_check.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/membrane/rigid_projection.hpp"

namespace bendlab {

namespace {
const MembraneParameters& checked(const MembraneParameters& p) {
  if (!(p.kS > 0) || !std::isfinite(p.kS)) throw Error(fmt::format("membrane: kS must be positive, got {}", p.kS));
  if (!(p.kB >= 0) || !std::isfinite(p.kB))
    throw Error(fmt::format("membrane: kB must be non-negative, got {}", p.kB));
  if (p.kB > 0 && p.bending == nullptr) throw Error("membrane: kB > 0 needs a bending method");
  if (!p.bending_terms.plain()) {
    if (!(p.kB > 0) || p.bending == nullptr)
      throw Error("membrane: c0 and ADE need a bending method and kB > 0");
    p.bending->check_parameters(p.bending_parameters());
  }
  return p;
}
}  // namespace

MembraneModel::MembraneModel(const TriMesh& reference, MembraneParameters parameters)
    : topology_(reference.topology_ptr()),
      reference_(reference.positions()),
      parameters_(checked(parameters)),
      elastic_(make_elastic_law(parameters_.elastic_law, topology_, reference_, parameters_.kS, parameters_.skalak_c)),
      reference_volume_(enclosed_volume(*topology_, reference_)),
      initial_(reference_),
      initial_volume_(reference_volume_) {}

MembraneModel::MembraneModel(const TriMesh& reference, MembraneParameters parameters, const Points& initial)
    : MembraneModel(reference, std::move(parameters)) {
  if (initial.rows() != topology_->num_vertices() || initial.cols() != 3)
    throw Error(fmt::format("membrane: {} initial positions for {} vertices", initial.rows(),
                            topology_->num_vertices()));
  require_finite_rows(initial, "membrane: the initial position");
  initial_ = initial;
  initial_volume_ = enclosed_volume(*topology_, initial_);
  if (!(initial_volume_ > 0))
    throw Error(fmt::format("membrane: the initial shape encloses the volume {}, not a positive one", initial_volume_));
}

void MembraneModel::forces(const Points& x, Points& force) const {
  if (x.rows() != topology_->num_vertices())
    throw Error(fmt::format("membrane: {} positions for {} vertices", x.rows(), topology_->num_vertices()));
  require_finite_rows(x, "membrane: the position");
  // Each stage is checked, so that a non-finite force names the stage it appeared in.
  elastic_->forces(x, force);
  require_finite_rows(force, "membrane: the " + parameters_.elastic_law + " elastic force");
  if (parameters_.bending != nullptr && parameters_.kB > 0) {
    Points bending;
    if (parameters_.bending_terms.plain())
      parameters_.bending->forces(*topology_, x, parameters_.kB, bending);
    else
      parameters_.bending->forces(*topology_, x, parameters_.bending_parameters(), bending);
    require_finite_rows(bending, "membrane: the bending force of method " + parameters_.bending->name());
    if (parameters_.bending_without_net_force) remove_rigid_motion(x, bending);
    force += bending;
  }
  if (parameters_.volume_force != nullptr) {
    parameters_.volume_force->add_forces(*topology_, x, initial_volume_, force);
    require_finite_rows(force, "membrane: the force with the volume force");
  }
}

MembraneForces MembraneModel::evaluate(const Points& x) const {
  MembraneForces r;
  forces(x, r.force);
  r.mixed_area = MeshGeometry::compute(*topology_, x).mixed_area;
  r.density = r.force.array().colwise() / r.mixed_area.array();  // eq. (14)
  return r;
}

void MembraneModel::force_density(const Points& x, Points& density) const {
  Points force;
  forces(x, force);
  const MeshGeometry geometry = MeshGeometry::compute(*topology_, x);
  density = force.array().colwise() / geometry.mixed_area.array();  // eq. (14)
  require_finite_rows(density, "membrane: the force density F / A_mixed");
}

double MembraneModel::elastic_energy(const Points& x) const { return elastic_->energy(x); }

std::optional<double> MembraneModel::bending_energy(const Points& x) const {
  if (parameters_.bending == nullptr) return std::nullopt;
  if (parameters_.bending_terms.plain()) return parameters_.bending->energy(*topology_, x, parameters_.kB);
  return parameters_.bending->energy(*topology_, x, parameters_.bending_parameters());
}

std::optional<double> MembraneModel::volume_energy(const Points& x) const {
  if (parameters_.volume_force == nullptr) return std::nullopt;
  return parameters_.volume_force->energy(*topology_, x, initial_volume_);
}

}  // namespace bendlab
