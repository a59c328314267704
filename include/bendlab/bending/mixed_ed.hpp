#pragma once
// Method ED, the mixture proposed in the paper's conclusion: "use approach E for H and D for the
// Laplace-Beltrami operator of H". The normal, H and K come from Method E's coordinate fit
// (farutin.hpp); lapH is Belkin's heat-kernel operator, eq. (13) with the half-space rule
// (belkin.hpp), applied to E's H; then f = 2 kB (lapH + 2 H (H^2 - K)) n, eq. (10), and
// F = f A_mixed, eq. (14). Cost O(N^2), like Method D.
#include <memory>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/bending/variational_assembly.hpp"

namespace bendlab {

class MixedEDMethod : public VariationalMethod {
 public:
  /// rings: neighbourhood of E's fit (option "rings", 1, 2 or 3).
  explicit MixedEDMethod(int rings = 1);
  ~MixedEDMethod() override;
  /// Option "rings" (1, 2, 3; default 1); throws bendlab::Error for any other option or value.
  static std::unique_ptr<BendingMethod> create(const MethodOptions& options);
  /// The method's entry in the registry (method_registry.hpp): description, options, capabilities.
  static MethodInfo info();

  std::string name() const override { return "ED"; }

 protected:
  /// n, H, K from E's fits, lapH from D's operator, the mixed area; eq. (10) and c0 / ADE are
  /// VariationalMethod's.
  void fields(const Topology& topology, const Points& x, BendingResult& out) const override;

 public:
  int rings() const { return rings_; }

 private:
  int rings_;
  struct Workspace;
  /// The geometry, the fits and the heat-kernel operator of the last call, kept between calls.
  MethodWorkspace<Workspace> workspace_;
};

}  // namespace bendlab
