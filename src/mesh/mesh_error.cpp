#include "bendlab/mesh/mesh_error.hpp"

namespace bendlab {

const char* to_string(MeshProblem p) {
  switch (p) {
    case MeshProblem::IndexOutOfRange: return "index out of range";
    case MeshProblem::RepeatedIndex: return "repeated index";
    case MeshProblem::ZeroArea: return "zero-area triangle";
    case MeshProblem::NonFinite: return "non-finite coordinate";
    case MeshProblem::OutOfRange: return "coordinates out of range";
    case MeshProblem::NonManifoldEdge: return "non-manifold edge";
    case MeshProblem::NonManifoldVertex: return "non-manifold vertex";
    case MeshProblem::BoundaryEdge: return "boundary edge";
    case MeshProblem::InconsistentOrientation: return "inconsistent orientation";
    case MeshProblem::InwardOrientation: return "inward orientation";
    case MeshProblem::UnreferencedVertex: return "unreferenced vertex";
    case MeshProblem::Empty: return "empty mesh";
  }
  return "invalid mesh";
}

}  // namespace bendlab
