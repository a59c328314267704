#pragma once
// The lattice Boltzmann capsule of the solver tests (serial and MPI): R = 4 dx in a 10 x 10 x 12
// box (2.5 R x 2.5 R x 3 R), 320 triangles, no bending, ESPResSo's volume force: a few hundred
// steps take milliseconds.
#include <memory>
#include <optional>

#include "bendlab/capsule/shear_units.hpp"
#include "bendlab/flow/lbm/ib_capsule_solver.hpp"
#include "bendlab/membrane/espresso_volume_force.hpp"
#include "bendlab/mesh/generators.hpp"

namespace bendlab::test {

inline LbmSolverOptions tiny_options(double G = 0.2) {
  lbm::CapsuleRunInput in;
  in.radius = 4;
  in.box_x = in.box_y = 2.5;
  in.box_z = 3;
  in.reynolds = 0.2;
  in.G = G;
  in.kB_hat = 0;
  in.gamma_t_end = 1;
  LbmSolverOptions o;
  o.radius = in.radius;
  o.lattice = lbm::capsule_run_parameters(in);
  o.sample_every = 0.01;
  return o;
}

inline std::shared_ptr<const MembraneModel> membrane(double G = 0.2) {
  MembraneParameters p;
  p.kS = ShearUnits::from(G, 0.0, std::nullopt).kS();
  p.volume_force = std::make_shared<const EspressoVolumeForce>(EspressoVolumeForce::for_membrane(p.kS));
  return std::make_shared<const MembraneModel>(sphere_mesh(MeshFamily::MT1, 2), p);
}

}  // namespace bendlab::test
