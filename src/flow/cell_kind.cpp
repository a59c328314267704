#include "bendlab/flow/cell_kind.hpp"

#include <fmt/format.h>

#include <cmath>

#include "bendlab/capsule/initial_shape.hpp"
#include "bendlab/elasticity/elastic_law.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/membrane/espresso_volume_force.hpp"
#include "bendlab/mesh/mesh_spec.hpp"

namespace bendlab {

namespace {
void require(bool ok, const std::string& message) {
  if (!ok) throw Error(message);
}
MethodOptions parse_options(const std::vector<std::string>& options) {
  MethodOptions parsed;
  for (const std::string& o : options) {
    const std::size_t eq = o.find('=');
    if (eq == std::string::npos || eq == 0) throw Error(fmt::format("--option '{}' is not name=value", o));
    parsed[o.substr(0, eq)] = o.substr(eq + 1);
  }
  return parsed;
}
}  // namespace

nlohmann::json CellKindSpec::to_json() const {
  nlohmann::json j = {{"cell", shape},
          {"cell_radius_um", radius_um},
          {"mesh", mesh},
          {"elastic_law", elastic_law},
          {"shear_modulus", shear_modulus},
          {"skalak_c", skalak_c},
          {"bending_modulus", bending_modulus},
          {"method", method},
          {"method_options", method_options},
          {"volume_modulus_ratio", volume_modulus_ratio}};
  if (bending_without_net_force) j["bending_without_net_force"] = true;
  return j;
}

void CellKindSpec::choose_bending_net_force(const std::optional<std::string>& choice) {
  if (choice && *choice != "keep" && *choice != "remove")
    throw Error(fmt::format("--bending-net-force (Python: bending_net_force) '{}' is not keep or remove", *choice));
  bending_without_net_force = choice ? *choice == "remove" : has_bending();
}

void check_cell_kind(const CellKindSpec& s) {
  require(s.shape == "rbc" || s.shape == "sphere", fmt::format("--cell '{}' is not a cell kind (rbc, sphere)", s.shape));
  require(s.radius_um > 0 && std::isfinite(s.radius_um), fmt::format("--cell-radius {} um must be finite and positive", s.radius_um));
  require(s.elastic_law == "skalak" || s.elastic_law == "neo-hookean",
          fmt::format("--membrane '{}' is not an elastic law (skalak, neo-hookean)", s.elastic_law));
  require(s.shear_modulus > 0 && std::isfinite(s.shear_modulus),
          fmt::format("--shear-modulus {} N/m must be finite and positive", s.shear_modulus));
  require(s.skalak_c > -0.5 && std::isfinite(s.skalak_c), fmt::format("--skalak-c {} must be finite and exceed -1/2", s.skalak_c));
  require(s.bending_modulus >= 0 && std::isfinite(s.bending_modulus),
          fmt::format("--bending-modulus {} J must be finite and not negative", s.bending_modulus));
  require(s.volume_modulus_ratio >= 0 && std::isfinite(s.volume_modulus_ratio),
          fmt::format("volume modulus ratio {} must be finite and not negative", s.volume_modulus_ratio));
  // The bending method and its options, before any work ("none": no bending force).
  if (s.method != "none") make_bending_method(s.method, parse_options(s.method_options));
  require(!s.bending_without_net_force || s.has_bending(),
          "--bending-net-force remove needs a bending force (a --method other than none and --bending-modulus > 0)");
}

CellKind make_cell_kind(const CellKindSpec& spec) {
  check_cell_kind(spec);
  CapsuleShapeSpec shape;
  shape.shape = spec.shape;
  const CapsuleGeometry g = capsule_geometry(mesh_from_spec(spec.mesh), shape);
  // capsule_geometry gives the shape at the volume of the unit sphere; the kind's radius is the
  // large half-axis (rbc) or the radius (sphere).
  const double scale = spec.radius_um / capsule_shape_measures(spec.shape).radial;
  Points x = g.reference.positions() * scale;
  const Vec3 c = volume_centroid(g.reference.topology(), x);
  x.rowwise() -= c.transpose();
  CellKind kind{spec, g.reference.with_positions(x), 0, 0, 0};
  kind.volume_um3 = enclosed_volume(kind.reference_um.topology(), x);
  kind.area_um2 = surface_area(kind.reference_um.topology(), x);
  kind.mean_edge_um = mean_edge_length(kind.reference_um.topology(), x);
  return kind;
}

std::optional<std::string> mesh_leak_warning(const CellKind& kind, double dx_um, double max_ratio) {
  const double ratio = kind.mean_edge_um / dx_um;
  if (ratio <= max_ratio) return std::nullopt;
  return fmt::format("warning: the {} mesh '{}' has edges of {:.3g} um on average, {:.2g} times dx = {} um: fluid leaks "
                     "through a membrane whose vertices lie more than about {} dx apart (use a finer mesh or a larger dx)",
                     kind.spec.shape, kind.spec.mesh, kind.mean_edge_um, ratio, dx_um, max_ratio);
}

std::shared_ptr<const MembraneModel> lattice_membrane(const CellKind& kind, const lbm::FlowUnits& units) {
  const CellKindSpec& s = kind.spec;
  MembraneParameters p;
  p.elastic_law = s.elastic_law;
  p.skalak_c = s.skalak_c;
  p.kS = units.to_lattice_modulus(3.0 * s.shear_modulus);  // k_S = 3 G_s
  p.kB = s.method == "none" ? 0.0 : units.to_lattice_energy(s.bending_modulus);
  if (p.kB > 0) p.bending = make_bending_method(s.method, parse_options(s.method_options));
  p.bending_without_net_force = s.bending_without_net_force;
  if (s.volume_modulus_ratio > 0) {
    // kappa_V = ratio kS / R: the capsule runs' kappa_V = 100 kS in units of the cell's radius
    // (cell_kind.hpp), here in lattice units, R = radius / dx.
    const double radius_lattice = s.radius_um / units.input.dx_um;
    p.volume_force = std::make_shared<const EspressoVolumeForce>(
        EspressoVolumeForce::for_membrane(p.kS / radius_lattice, s.volume_modulus_ratio));
  }
  const TriMesh lattice_mesh = kind.reference_um.with_positions(kind.reference_um.positions() / units.input.dx_um);
  return std::make_shared<const MembraneModel>(lattice_mesh, std::move(p));
}

std::shared_ptr<const MembraneModel> physical_membrane(const CellKind& kind) {
  const CellKindSpec& s = kind.spec;
  MembraneParameters p;
  p.elastic_law = s.elastic_law;
  p.skalak_c = s.skalak_c;
  p.kS = 3.0 * s.shear_modulus * 1e6;  // k_S = 3 G_s; N/m -> pN/um
  p.kB = s.bending_modulus * 1e18;     // J -> pN um
  if (p.kB > 0) p.bending = make_bending_method(s.method, parse_options(s.method_options));
  p.bending_without_net_force = s.bending_without_net_force;
  if (s.volume_modulus_ratio > 0)
    p.volume_force = std::make_shared<const EspressoVolumeForce>(s.volume_modulus_ratio * p.kS / s.radius_um);
  return std::make_shared<const MembraneModel>(kind.reference_um, std::move(p));
}

}  // namespace bendlab
