// The factory of bending methods by name (bending_method.hpp).
#include <fmt/format.h>

#include "bendlab/bending/belkin.hpp"
#include "bendlab/bending/bending_method.hpp"
#include "bendlab/bending/farutin.hpp"
#include "bendlab/bending/gompper_kroll.hpp"
#include "bendlab/bending/kantor_nelson.hpp"
#include "bendlab/bending/loop_shell.hpp"
#include "bendlab/bending/meyer.hpp"
#include "bendlab/bending/mixed_ed.hpp"

namespace bendlab {

std::unique_ptr<BendingMethod> make_bending_method(const std::string& name, const MethodOptions& options) {
  if (name == "A") return KantorNelson::create(options);
  if (name == "B") return GompperKroll::create(options);
  if (name == "C") return MeyerMethod::create(options);
  if (name == "D") return BelkinMethod::create(options);
  if (name == "E") return FarutinMethod::create(options);
  if (name == "ED") return MixedEDMethod::create(options);
  if (name == "S") return LoopShellMethod::create(options);
  throw Error(fmt::format("unknown bending method '{}': expected A, B, C, D, E or ED", name));
}

}  // namespace bendlab
