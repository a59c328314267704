// A bending method registered from outside the library takes part in the RBC study like the
// built-ins (bending/method_registry.hpp, analysis/rbc_study.hpp).
#include <gtest/gtest.h>

#include "bendlab/analysis/rbc_study.hpp"
#include "bendlab/bending/meyer.hpp"

using namespace bendlab;

namespace {

constexpr const char* kToy = "study-test-toy";

// Method C with its force density and force scaled by the option "scale".
class ScaledMeyer final : public BendingMethod {
 public:
  explicit ScaledMeyer(double scale) : scale_(scale) {}
  std::string name() const override { return kToy; }
  BendingResult compute(const Topology& t, const Points& x, double kappa_b) const override {
    BendingResult r = MeyerMethod().compute(t, x, kappa_b);
    r.force *= scale_;
    r.force_density *= scale_;
    return r;
  }

 private:
  double scale_;
};

void register_toy() {
  if (find_bending_method(kToy)) return;
  MethodInfo m{kToy, "Method C with scaled forces (a test of the registry)",
               {real_option("scale", 0, 10, 1, "force factor")},
               {},
               [](const MethodOptions& o) { return std::make_unique<ScaledMeyer>(option_real(o, "scale")); }};
  register_bending_method(std::move(m));
}

const ErrorSummary& summary(const MeshRun& m, const std::string& method, Quantity q) {
  for (const MethodRun& r : m.methods)
    if (r.method == method) return r.errors[static_cast<int>(q)];
  throw Error("no run of " + method);
}

}  // namespace

TEST(MethodRegistryStudy, ARegisteredMethodRunsInTheStudy) {
  register_toy();
  RbcStudyOptions o;
  EXPECT_EQ(o.methods.back(), kToy);  // the default list is every registered method
  o.families = {"mt1"};
  o.max_triangles = 320;
  o.methods = {"C", kToy};
  RbcStudyResult r = run_rbc_study(o);
  ASSERT_EQ(r.meshes.size(), 1u);
  const MeshRun& m = r.meshes[0];
  ASSERT_EQ(m.methods.size(), 2u);
  EXPECT_EQ(m.methods[1].method, kToy);
  // scale = 1 (the default): the same numbers as Method C, quantity by quantity.
  for (Quantity q : kAllQuantities) {
    EXPECT_EQ(summary(m, kToy, q).available, summary(m, "C", q).available);
    if (summary(m, "C", q).available) EXPECT_EQ(summary(m, kToy, q).max, summary(m, "C", q).max);
  }
  // The study passes the toy its option (and only the toy: C takes none): f changes, H does not.
  o.method_options = {{"scale", "2"}};
  r = run_rbc_study(o);
  const MeshRun& m2 = r.meshes[0];
  EXPECT_EQ(summary(m2, kToy, Quantity::H).max, summary(m2, "C", Quantity::H).max);
  EXPECT_NE(summary(m2, kToy, Quantity::F).max, summary(m2, "C", Quantity::F).max);
  // Its schema is enforced through the study too, and an option no method takes is refused.
  o.method_options = {{"scale", "-1"}};
  EXPECT_THROW(validate(o), Error);
  o.method_options = {{"no_such_option", "1"}};
  EXPECT_THROW(validate(o), Error);
}
