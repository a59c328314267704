#pragma once
// The static red-blood-cell benchmark of the paper's section 3.
//
// For every requested mesh family and refinement level with N_T <= max_triangles:
//   unit-sphere mesh (sphere_mesh) -> RBC of eq. (15) (make_rbc()->map_from_unit_sphere, same
//   topology) -> every bending method -> error measures of eq. (17) against the exact fields.
//
// Families and the meshes they give (family names as written in errors.csv):
//   "mt1", "mt2"       levels 2, 3, ... : N_T = 320, 1280, 5120, 20480, 81920
//   "octa"             levels 3, 4, ... : N_T = 512, 2048, 8192, ...
//   "inhomogeneous"    "rivara-mt1" and "rivara-mt2": level 2 (320 triangles) of MT1 / MT2, then
//                      three Rivara passes (about 3900 triangles). These two meshes are run
//                      whatever max_triangles is, because table 3 needs them. Method S refuses
//                      them (MethodRun::refused).
//   "irregular"        levels 2, 3, ... of MT1 with every node jittered tangentially by `jitter`
//                      times its mean edge length, seed jitter_seed + level (jitter.hpp), so the
//                      meshes stay irregular under refinement: N_T = 320, 1280, ..., 81920
// h is the mean edge length of the mapped (RBC) mesh.
#include <functional>
#include <string>
#include <vector>

#include "bendlab/analysis/convergence.hpp"
#include "bendlab/analysis/error_measures.hpp"
#include "bendlab/bending/method_registry.hpp"
#include "bendlab/mesh/jitter.hpp"
#include "bendlab/mesh/trimesh.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

namespace bendlab {

struct RbcStudyOptions {
  std::vector<std::string> families = {"mt1", "mt2", "octa", "inhomogeneous", "irregular"};
  /// Every registered method by default (method_registry.hpp), in the registry's order.
  std::vector<std::string> methods = bending_method_names();
  /// Method options (e.g. {"rings", "2"}), each passed to the methods whose schema has it (rings:
  /// E and ED); an option that no registered method takes is an error.
  MethodOptions method_options;
  int max_triangles = 5120;
  /// Orientation of the icosahedron of MT1 and MT2: "default" (vertices at (+-1, +-phi, 0) / |.|,
  /// four on the equator, i.e. on the RBC's rim) or "polar" (icosahedron_polar(): a vertex at each
  /// pole). Method S's errors depend on it (the extraordinary vertices' positions); the other
  /// methods' hardly.
  std::string base = "default";
  /// The irregular family: the fraction of its mean edge length by which each node moves, and the
  /// base seed (level k: jitter_seed + k). The jitter is applied to MT1 of `base`.
  double jitter = kDefaultJitterFraction;
  std::uint64_t jitter_seed = kDefaultJitterSeed;
  double kappa_b = 1.0;
  /// Spontaneous curvature and ADE (docs/conventions.md §5): the exact force density of the RBC is
  /// then the general force law from its exact H, K, Lap H, with M and the ADE area A those of the
  /// exact shape. All zero: the paper's study, unchanged.
  double c0 = 0.0, ade_alpha = 0.0, ade_d = 0.0, ade_da0 = 0.0;
  double radius = 1.0;
  /// Per-node data (numerical results, errors) are kept for meshes with N_T <= this, and for the
  /// inhomogeneous meshes; larger meshes keep only the summaries.
  int keep_nodes_max_triangles = 5120;
  /// Called with one line per mesh and per method (with the time taken); may be empty.
  std::function<void(const std::string&)> progress;
};

/// The families a study accepts.
const std::vector<std::string>& rbc_study_families();
/// Throws bendlab::Error (one line) for an unknown family or method, max_triangles < 320, a
/// non-positive kappa_b or radius, method options that a method refuses, or a jitter that folds a
/// triangle of an irregular mesh of the study (the irregular meshes are generated to check that).
void validate(const RbcStudyOptions& options);
/// The membrane parameters of a study: kB, c0 and ADE with A = the exact area of the RBC.
BendingParameters rbc_bending_parameters(const RbcStudyOptions& options);

struct MethodRun {
  std::string method;
  /// Non-empty when the method refused the mesh (the bendlab::Error it threw, one line): only a
  /// method whose capabilities say needs_admissible_mesh may refuse (Method S on the Rivara
  /// meshes, two extraordinary vertices in a triangle); its errors are then all unavailable and
  /// the tables show n/a with this reason. Any other method's Error ends the study.
  std::string refused;
  double seconds = 0;                  ///< wall time of BendingMethod::compute
  std::vector<ErrorSummary> errors;    ///< by kAllQuantities
  bool has_nodes = false;
  BendingResult result;                ///< when has_nodes
  NodeErrors node_errors;              ///< when has_nodes
};

struct MeshRun {
  std::string family;        ///< "mt1", "mt2", "octa", "rivara-mt1", "rivara-mt2", "irregular"
  std::string origin;        ///< homogeneous family of the mesh ("mt1" for "rivara-mt1")
  bool inhomogeneous = false;
  int level = 0, triangles = 0, vertices = 0;
  double h = 0;              ///< mean edge length on the RBC
  bool has_nodes = false;
  TopologyPtr topology;      ///< when has_nodes
  Points x;                  ///< RBC node positions, when has_nodes
  Scalars theta;             ///< polar angle, eq. (16), when has_nodes
  SurfaceFields analytic;    ///< exact fields at the nodes, when has_nodes
  std::vector<MethodRun> methods;
};

struct RbcStudyResult {
  RbcStudyOptions options;
  SurfaceMaxima maxima;      ///< denominators of eq. (17)
  std::vector<MeshRun> meshes;

  /// One row per mesh, method and available quantity, in run order.
  std::vector<ErrorRow> rows() const;
};

RbcStudyResult run_rbc_study(const RbcStudyOptions& options);

/// Polar angle of each node, eq. (16): theta_i = arccos(z_i / |x_i|), in [0, pi].
Scalars polar_angle(const Points& x);

/// Markdown of table 2 for one family and measure ("max" or "avg"): rows K, H, lapH, f, n;
/// one column per method; each cell the symbol and the slope on the finest meshes.
std::string table2_markdown(const std::vector<RateFit>& fits, const std::string& family, const std::string& measure,
                            const std::vector<std::string>& methods);
/// Markdown of table 3 for one inhomogeneous family: symbol and the ratios max / avg; "n/a" for the
/// methods in `refused` (they refused the mesh).
std::string table3_markdown(const std::vector<InhomogeneityCheck>& checks, const std::vector<std::string>& methods,
                            const std::vector<std::string>& refused = {});

}  // namespace bendlab
