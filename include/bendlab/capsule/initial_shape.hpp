#pragma once
// The initial and the stress-free (reference) shape of a capsule (docs/conventions.md §2, "Capsule
// shapes"). The paper's capsule is a sphere that is both; a red blood cell starts biconcave and is
// stress-free there, or, as some studies take it, stress-free as a spheroid of its own area.
//
// A shape maps the mesh's unit-sphere points (its nodes, normalised about the volume centroid)
// onto an analytic surface of revolution about z (surfaces/analytic_surface.hpp):
//   sphere   radius 1: the mesh as it is, untouched (the default, as in the paper);
//   rbc      the red blood cell of eq. (15), scaled so that its volume is 4 pi / 3, that of the
//            sphere of radius R = 1 (analytic volume; large half-axis 1.3858... R);
//   oblate   the spheroid of half-axes (a, a, c), c / a = aspect < 1, of volume 4 pi / 3;
//   prolate  the same with c / a = aspect > 1.
// A reference shape other than the initial one is mapped from the same unit-sphere points (the same
// node is the same material point) and scaled so that its analytic area equals the initial
// shape's: the membrane is then as large as its reference, only differently curved.
// Both shapes are then turned about e_y by the tilt: the axis of symmetry e_z goes to
// (sin tilt, 0, cos tilt), in the shear plane x-z, tilted from e_z towards e_x (the sense in which
// the shear flow u = gamma z e_x turns a body).
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/trimesh.hpp"

namespace bendlab {

struct CapsuleShapeSpec {
  std::string shape = "sphere";      ///< initial shape: sphere, rbc, oblate, prolate
  std::optional<double> aspect;      ///< c / a of a spheroid; none: the default (oblate 0.5, prolate 2)
  double tilt_degrees = 0;           ///< angle of the axis of symmetry from e_z towards e_x, in [-180, 180]
  std::string reference = "initial";  ///< stress-free shape: initial (the initial one), or a shape name
  std::optional<double> reference_aspect;  ///< c / a of a spheroidal reference; none: the default
  /// The sphere, untilted, stress-free as it starts: the paper's capsule.
  bool is_default() const { return shape == "sphere" && tilt_degrees == 0 && reference == "initial"; }
};

/// The shape names: sphere, rbc, oblate, prolate.
std::vector<std::string> capsule_shape_names();

/// Throws bendlab::Error with a one-line message naming the option (--shape, --aspect, --tilt,
/// --reference-shape, --reference-aspect) for an unknown shape, an aspect ratio that does not fit
/// the shape (oblate: in (0, 1), prolate: > 1, none for sphere and rbc; 0 is refused, not taken for
/// the default), a tilt out of range or not finite.
void check_capsule_shape(const CapsuleShapeSpec& spec);

struct CapsuleGeometry {
  TriMesh reference;  ///< the stress-free mesh (the elastic law's reference)
  Points initial;     ///< the positions the run starts from
  /// shape, aspect, tilt, the reference's, and the initial shape's analytic volume, area and
  /// reduced volume v = 3 V / (4 pi (A / 4 pi)^(3/2)); for summary.json.
  nlohmann::json description;
};

/// The initial and reference shapes of `spec` on the nodes of `mesh` (a closed mesh of the unit
/// sphere, or any closed star-shaped mesh: its nodes are normalised about its volume centroid).
/// For the default spec, both are mesh.positions() unchanged. Checks spec as check_capsule_shape,
/// and refuses (naming --shape or --reference-shape) a mesh that the map onto a shape would fold:
/// one not star-shaped about its centroid, whose directions from it give a triangle that is
/// inverted or degenerate.
CapsuleGeometry capsule_geometry(const TriMesh& mesh, const CapsuleShapeSpec& spec);

/// Analytic volume and area of a shape of spec (before tilting; the sphere: 4 pi / 3 and 4 pi).
struct ShapeMeasures {
  double volume = 0, area = 0, reduced_volume = 0;
  double radial = 0, height = 0;  ///< largest radius about the axis and largest |z| (half-thickness)
};
ShapeMeasures capsule_shape_measures(const std::string& shape, std::optional<double> aspect = std::nullopt);

}  // namespace bendlab
