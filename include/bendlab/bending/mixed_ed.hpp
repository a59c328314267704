#pragma once
// Method ED, the mixture proposed in the paper's conclusion: "use approach E for H and D for the
// Laplace-Beltrami operator of H". The normal, H and K come from Method E's coordinate fit
// (farutin.hpp); lapH is Belkin's heat-kernel operator, eq. (13) with the half-space rule
// (belkin.hpp), applied to E's H; then f = 2 kB (lapH + 2 H (H^2 - K)) n, eq. (10), and
// F = f A_mixed, eq. (14). Cost O(N^2), like Method D.
#include <memory>

#include "bendlab/bending/method_registry.hpp"

namespace bendlab {

class MixedEDMethod : public BendingMethod {
 public:
  /// rings: neighbourhood of E's fit (option "rings", 1, 2 or 3).
  explicit MixedEDMethod(int rings = 1);
  /// Option "rings" (1, 2, 3; default 1); throws bendlab::Error for any other option or value.
  static std::unique_ptr<BendingMethod> create(const MethodOptions& options);
  /// The method's entry in the registry (method_registry.hpp): description, options, capabilities.
  static MethodInfo info();

  std::string name() const override { return "ED"; }
  BendingResult compute(const Topology& topology, const Points& x, double kappa_b) const override;

 protected:
  /// c0 and ADE through the force law of docs/conventions.md §5 (variational_assembly.hpp).
  bool supports_membrane_terms() const override { return true; }
  BendingResult compute_terms(const Topology& topology, const Points& x, const BendingParameters& params) const override;

 public:
  int rings() const { return rings_; }

 private:
  int rings_;
};

}  // namespace bendlab
