#pragma once
// Method C (paper section 2.4.1): the force density of eq. (10) evaluated with Meyer et al.'s
// discrete operators.
//
//   normal  n_i  : "mean weighted by angle" (MWA) of the face normals;
//   H_i          : eq. (2), H = -1/2 (Lap x) . n, with the cotangent Laplacian of eq. (11) and
//                  a_i = A_mixed_i (positive on a sphere);
//   lapH_i       : eq. (11) applied again, to H;
//   K_i          : angle defect over the mixed area, eq. (12);
//   f_i          : eq. (10), f = 2 kB (lapH + 2 H (H^2 - K)) n (docs/conventions.md sign);
//   F_i          : f_i A_mixed_i, eq. (14); area = A_mixed.
// The paper writes eq. (11) as sum T_ij (w_i - w_j); here the Laplacian is div grad
// (sum T_ij (w_j - w_i)), the sign with which eq. (10) holds. Method C has no energy. The last step,
// eqs. (10) and (14), is assemble_variational_result (variational_assembly.hpp), shared with D, E, ED.
#include <memory>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/bending/variational_assembly.hpp"

namespace bendlab {

class MeyerMethod final : public VariationalMethod {
 public:
  MeyerMethod();
  ~MeyerMethod() override;
  /// Method C has no options; any option is an error (bendlab::Error naming it).
  static std::unique_ptr<BendingMethod> create(const MethodOptions& options);
  /// The method's entry in the registry (method_registry.hpp): description, options, capabilities.
  static MethodInfo info();

  std::string name() const override { return "C"; }

 protected:
  /// n, H, K, lapH and the mixed area; eq. (10) and c0 / ADE are VariationalMethod's.
  void fields(const Topology& topology, const Points& x, BendingResult& out) const override;

 private:
  struct Workspace;
  /// The geometry and Lap x of the last call, kept between calls.
  MethodWorkspace<Workspace> workspace_;
};

}  // namespace bendlab
