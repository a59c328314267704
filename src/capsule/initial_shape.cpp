#include "bendlab/capsule/initial_shape.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "bendlab/geometry/measures.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"
#include "bendlab/surfaces/surface_of_revolution.hpp"

namespace bendlab {

namespace {

double default_aspect(const std::string& shape) { return shape == "oblate" ? 0.5 : shape == "prolate" ? 2.0 : 0.0; }

// aspect: none is the shape's default; any value given, 0 included, must fit the shape.
void check_shape(const std::string& shape, std::optional<double> aspect, const char* shape_option,
                 const char* aspect_option) {
  if (shape != "sphere" && shape != "rbc" && shape != "oblate" && shape != "prolate")
    throw Error(fmt::format("{} '{}': the shapes are sphere, rbc, oblate, prolate", shape_option, shape));
  if (!aspect) return;
  if (!std::isfinite(*aspect)) throw Error(fmt::format("{} must be finite, got {}", aspect_option, *aspect));
  if (shape == "oblate" && !(*aspect > 0 && *aspect < 1))
    throw Error(fmt::format("{} {}: an oblate spheroid needs c / a in (0, 1)", aspect_option, *aspect));
  if (shape == "prolate" && !(*aspect > 1))
    throw Error(fmt::format("{} {}: a prolate spheroid needs c / a > 1", aspect_option, *aspect));
  if (shape == "sphere" || shape == "rbc")
    throw Error(fmt::format("{} is for a spheroid (oblate, prolate), not the {}", aspect_option, shape));
}

/// The unit-size surface of a shape: radius 1 (sphere, rbc), half-axes (1, 1, aspect) (spheroids).
std::unique_ptr<SurfaceOfRevolution> unit_surface(const std::string& shape, std::optional<double> aspect,
                                                  double scale) {
  std::unique_ptr<AnalyticSurface> s;
  if (shape == "rbc") s = make_rbc(scale);
  else if (shape == "sphere") s = make_sphere(scale);
  else s = make_spheroid(scale, scale * aspect.value_or(default_aspect(shape)));
  return std::unique_ptr<SurfaceOfRevolution>(static_cast<SurfaceOfRevolution*>(s.release()));
}

/// Volume pi int r^2 n_r s' dt and area 2 pi int r s' dt over t in [0, pi] (composite Simpson,
/// the integrands are smooth and periodic-like; 4096 intervals give round-off accuracy), and the
/// largest r and |z|.
ShapeMeasures measures_of(const SurfaceOfRevolution& s) {
  const int n = 4096;
  const double h = M_PI / n;
  double v = 0, a = 0;
  ShapeMeasures m;
  for (int k = 0; k <= n; ++k) {
    const MeridianValues mv = s.meridian(k * h);
    const double w = (k == 0 || k == n) ? 1 : (k % 2 ? 4 : 2);
    v += w * mv.r * mv.r * mv.n_r * mv.ds_dt;
    a += w * mv.r * mv.ds_dt;
    m.radial = std::max(m.radial, mv.r);
    m.height = std::max(m.height, std::abs(mv.z));
  }
  m.volume = M_PI * v * h / 3;
  m.area = 2 * M_PI * a * h / 3;
  m.reduced_volume = 3 * m.volume / (4 * M_PI * std::pow(m.area / (4 * M_PI), 1.5));
  return m;
}

/// The shape scaled to the volume 4 pi / 3 (initial), or to the area `area` (reference, area > 0).
std::unique_ptr<SurfaceOfRevolution> scaled_surface(const std::string& shape, std::optional<double> aspect,
                                                    double area) {
  const ShapeMeasures unit = measures_of(*unit_surface(shape, aspect, 1.0));
  const double scale = area > 0 ? std::sqrt(area / unit.area) : std::cbrt(4 * M_PI / 3 / unit.volume);
  return unit_surface(shape, aspect, scale);
}

Points unit_directions(const TriMesh& mesh) {
  Points u = mesh.positions();
  u.rowwise() -= volume_centroid(mesh.topology(), u).transpose();
  for (Eigen::Index i = 0; i < u.rows(); ++i) {
    const double len = u.row(i).norm();
    if (!(len > 0)) throw Error(fmt::format("--shape: mesh node {} lies at the mesh's centroid", i));
    u.row(i) /= len;
  }
  return u;
}

/// Refuses a mesh the map would fold. A shape is mapped from the directions u of the nodes seen
/// from the volume centroid; for a mesh star-shaped about it every triangle of u turns as the
/// outward normal does, u0 . (u1 x u2) > 0. A triangle whose value is not positive (to
/// round-off against the mean) comes out of the map inverted or degenerate: the mapped surface
/// would be folded, and a run on it meaningless.
void check_unfolded(const TriMesh& mesh, const Points& u, const std::string& option, const std::string& shape) {
  const Faces& faces = mesh.topology().faces();
  std::vector<double> turn(static_cast<std::size_t>(faces.rows()));
  double mean = 0;
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Vec3 a = u.row(faces(f, 0)), b = u.row(faces(f, 1)), c = u.row(faces(f, 2));
    turn[static_cast<std::size_t>(f)] = a.dot(b.cross(c));
    mean += std::abs(turn[static_cast<std::size_t>(f)]);
  }
  mean /= std::max<double>(1.0, static_cast<double>(faces.rows()));
  std::int64_t folded = 0, first = -1;
  for (std::size_t f = 0; f < turn.size(); ++f)
    if (!(turn[f] > 1e-9 * mean)) {
      if (first < 0) first = static_cast<std::int64_t>(f);
      ++folded;
    }
  if (folded > 0)
    throw Error(fmt::format("{} {}: the mesh is not star-shaped about its volume centroid: mapped onto the shape, {} "
                            "of its {} triangles would be inverted or degenerate (the first: triangle {}); a shape is "
                            "mapped from a mesh of the sphere, or any closed mesh star-shaped about its centroid",
                            option, shape, folded, faces.rows(), first));
}

}  // namespace

std::vector<std::string> capsule_shape_names() { return {"sphere", "rbc", "oblate", "prolate"}; }

void check_capsule_shape(const CapsuleShapeSpec& s) {
  check_shape(s.shape, s.aspect, "--shape", "--aspect");
  if (s.reference != "initial") check_shape(s.reference, s.reference_aspect, "--reference-shape", "--reference-aspect");
  else if (s.reference_aspect) throw Error("--reference-aspect is for a --reference-shape other than initial");
  if (!std::isfinite(s.tilt_degrees) || std::abs(s.tilt_degrees) > 180)
    throw Error(fmt::format("--tilt must be an angle in degrees within [-180, 180], got {}", s.tilt_degrees));
}

ShapeMeasures capsule_shape_measures(const std::string& shape, std::optional<double> aspect) {
  check_shape(shape, aspect, "shape", "aspect");
  return measures_of(*scaled_surface(shape, aspect, 0));
}

namespace {
CapsuleGeometry shapes_of(const TriMesh& mesh, const CapsuleShapeSpec& s);
}

CapsuleGeometry capsule_geometry(const TriMesh& mesh, const CapsuleShapeSpec& s) {
  CapsuleGeometry g = shapes_of(mesh, s);
  // The discrete shape's measures, beside the analytic ones.
  const double v = enclosed_volume(g.reference.topology(), g.initial);
  const double area = surface_area(g.reference.topology(), g.initial);
  g.description["mesh_volume"] = v;
  g.description["mesh_area"] = area;
  g.description["mesh_reduced_volume"] = 3 * v / (4 * M_PI * std::pow(area / (4 * M_PI), 1.5));
  return g;
}

namespace {
CapsuleGeometry shapes_of(const TriMesh& mesh, const CapsuleShapeSpec& s) {
  check_capsule_shape(s);
  const ShapeMeasures initial_measures = capsule_shape_measures(s.shape, s.aspect);
  CapsuleGeometry g{mesh, mesh.positions(), nlohmann::json::object()};
  const double aspect = s.aspect.value_or(default_aspect(s.shape));
  g.description = {{"shape", s.shape},
                   {"tilt_degrees", s.tilt_degrees},
                   {"reference_shape", s.reference},
                   {"analytic_volume", initial_measures.volume},
                   {"analytic_area", initial_measures.area},
                   {"reduced_volume", initial_measures.reduced_volume}};
  if (aspect != 0) g.description["aspect"] = aspect;
  if (s.is_default()) return g;
  const Points u = unit_directions(mesh);
  if (s.shape != "sphere") check_unfolded(mesh, u, "--shape", s.shape);
  else if (s.reference != "initial") check_unfolded(mesh, u, "--reference-shape", s.reference);
  Points initial = s.shape == "sphere" ? u : scaled_surface(s.shape, s.aspect, 0)->map_from_unit_sphere(u);
  Points reference = initial;
  if (s.reference != "initial") {
    reference = scaled_surface(s.reference, s.reference_aspect, initial_measures.area)->map_from_unit_sphere(u);
    const double ra = s.reference_aspect.value_or(default_aspect(s.reference));
    if (ra != 0) g.description["reference_aspect"] = ra;
  }
  // The sphere keeps the mesh's own nodes (a mesh file need not lie on the unit sphere).
  if (s.shape == "sphere") initial = mesh.positions();
  if (s.shape == "sphere" && s.reference == "initial") reference = initial;
  // Turn about e_y: e_z -> (sin a, 0, cos a), e_x -> (cos a, 0, -sin a).
  const double a = s.tilt_degrees * M_PI / 180;
  const Mat3 R = Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix();
  initial = (initial * R.transpose()).eval();
  reference = (reference * R.transpose()).eval();
  g.initial = initial;
  g.reference = mesh.with_positions(reference);
  return g;
}
}  // namespace

}  // namespace bendlab
