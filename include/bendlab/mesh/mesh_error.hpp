#pragma once
// The reasons a triangle mesh is refused, and the exception that carries one.
#include <string>

#include "bendlab/core/types.hpp"

namespace bendlab {

enum class MeshProblem {
  IndexOutOfRange,          ///< a face refers to a vertex that does not exist
  RepeatedIndex,            ///< a face names the same vertex twice
  ZeroArea,                 ///< a triangle with (numerically) zero area
  NonFinite,                ///< a coordinate that is NaN or infinite
  OutOfRange,               ///< coordinates so large or a mesh so small that areas or volumes over/underflow
  NonManifoldEdge,          ///< an edge shared by more than two faces
  NonManifoldVertex,        ///< the faces around a vertex form more than one fan
  BoundaryEdge,             ///< an edge with one face: the surface is open
  InconsistentOrientation,  ///< two faces traverse their shared edge in the same direction
  InwardOrientation,        ///< negative enclosed volume: faces are clockwise seen from outside
  UnreferencedVertex,       ///< a vertex that belongs to no face
  Empty,                    ///< no vertices or no faces
};

/// Short machine-friendly name ("boundary edge", ...), used at the start of every message.
const char* to_string(MeshProblem p);

class MeshError : public Error {
 public:
  MeshError(MeshProblem problem, const std::string& detail)
      : Error(std::string(to_string(problem)) + ": " + detail), problem_(problem) {}
  MeshProblem problem() const { return problem_; }

 private:
  MeshProblem problem_;
};

}  // namespace bendlab
