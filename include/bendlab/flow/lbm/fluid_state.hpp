#pragma once
// The solver state of a lattice Boltzmann run in its checkpoint (capsule_solver.hpp's
// SolverState), shared by the capsule solvers (ib_capsule_solver.hpp) and the suspension
// (lbm_suspension_solver.hpp):
//   {"fluid": "lbm_fluid_<tag>.bin" (the lattice, checkpoint.hpp, written atomically),
//    "lattice_step": n, "positions_lattice": [3N numbers, the vertices in dx]}
// The vertices are kept in lattice units so that a resumed run repeats the uninterrupted one bit
// for bit (the run's own positions are scaled and would round).
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "bendlab/core/types.hpp"

namespace bendlab::lbm {

/// Whether `name` is a fluid file of a checkpoint: lbm_fluid_NNNNN.bin.
bool is_fluid_file(const std::string& name);
/// lbm_fluid_<tag>.bin.
std::string fluid_file_name(const std::string& tag);

nlohmann::json fluid_state_fields(const std::string& fluid, std::int64_t lattice_step, const Points& X);

struct FluidStateFields {
  std::string fluid;
  std::int64_t lattice_step = 0;
  Points X;
};

/// Validates `fields` for `rows` vertices; throws bendlab::Error naming `source`, "solver_state"
/// and the key.
FluidStateFields parse_fluid_state(const nlohmann::json& fields, Eigen::Index rows, const std::string& source);

}  // namespace bendlab::lbm
