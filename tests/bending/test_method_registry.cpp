// The table of bending methods (bending/method_registry.hpp): the built-ins, option schemas and
// their validation, and a method registered from outside the library.
#include <gtest/gtest.h>

#include <cmath>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/bending/meyer.hpp"
#include "bendlab/mesh/generators.hpp"

using namespace bendlab;

namespace {

// Throws an Error whose message contains `part`.
template <class F>
void expect_error_naming(F&& f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one naming '" << part << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

// A toy method: Method C with its force scaled by the option "scale".
class ScaledMeyer final : public BendingMethod {
 public:
  explicit ScaledMeyer(double scale) : scale_(scale) {}
  std::string name() const override { return "registry-test-toy"; }
  BendingResult compute(const Topology& t, const Points& x, double kappa_b) const override {
    BendingResult r = MeyerMethod().compute(t, x, kappa_b);
    r.force *= scale_;
    r.force_density *= scale_;
    return r;
  }
  double scale_;
};

MethodInfo toy_info() {
  MethodInfo m{"registry-test-toy", "Method C with scaled forces (a test of the registry)",
               {real_option("scale", 0, 10, 1, "force factor")},
               {},
               [](const MethodOptions& o) { return std::make_unique<ScaledMeyer>(option_real(o, "scale")); }};
  return m;
}

}  // namespace

TEST(MethodRegistry, ListsTheBuiltInsInTableOrder) {
  const std::vector<std::string> names = bending_method_names();
  ASSERT_GE(names.size(), 9u);
  EXPECT_EQ(std::vector<std::string>(names.begin(), names.begin() + 9),
            (std::vector<std::string>{"A", "B", "C", "D", "E", "ED", "S", "J", "M"}));
  for (const std::string& n : {"A", "B", "C", "D", "E", "ED", "S", "J", "M"}) {
    const MethodInfo& info = bending_method_info(n);
    EXPECT_FALSE(info.description.empty()) << n;
    // The factory makes the method of that name, with the defaults.
    EXPECT_EQ(make_bending_method(n)->name(), n);
  }
  EXPECT_TRUE(bending_method_info("A").capabilities.has_energy);
  EXPECT_TRUE(bending_method_info("B").capabilities.has_energy);
  EXPECT_FALSE(bending_method_info("C").capabilities.has_energy);
  EXPECT_FALSE(bending_method_info("A").capabilities.defines_H);
  EXPECT_FALSE(bending_method_info("B").capabilities.defines_lapH);
  EXPECT_EQ(bending_method_info("D").capabilities.cost, "O(N)");  // the cell list (neighbours=grid)
  ASSERT_EQ(bending_method_info("D").options.size(), 2u);
  EXPECT_EQ(bending_method_info("D").options[0].name, "neighbours");
  EXPECT_EQ(bending_method_info("D").options[0].choices, (std::vector<std::string>{"grid", "all"}));
  EXPECT_EQ(bending_method_info("D").options[1].name, "kernel_cutoff");
  EXPECT_NO_THROW(make_bending_method("D", {{"neighbours", "all"}}));
  expect_error_naming([] { make_bending_method("D", {{"neighbours", "some"}}); }, "neighbours");
  EXPECT_EQ(bending_method_info("E").options.size(), 1u);
  EXPECT_EQ(bending_method_info("E").options[0].name, "rings");
  const MethodInfo& s = bending_method_info("S");
  EXPECT_TRUE(s.capabilities.has_energy);
  EXPECT_FALSE(s.capabilities.defines_lapH);
  EXPECT_TRUE(s.capabilities.needs_admissible_mesh);
  ASSERT_EQ(s.options.size(), 4u);
  EXPECT_EQ(s.options[1].name, "gauss");
  EXPECT_EQ(s.options[1].default_value, "6");
  expect_error_naming([] { make_bending_method("S", {{"gauss", "5"}}); }, "gauss");
  expect_error_naming([] { make_bending_method("S", {{"solver", "lu"}}); }, "solver");
  EXPECT_EQ(find_bending_method("Z"), nullptr);
  expect_error_naming([] { bending_method_info("Z"); }, "'Z'");
  expect_error_naming([] { make_bending_method("Z"); }, "ED");  // the message lists the known methods
}

TEST(MethodRegistry, CapabilitiesMatchWhatTheMethodsCompute) {
  // 320 triangles: on 80, Method M's degree-6 jet is not determined even by the whole sphere.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  for (const MethodInfo& info : bending_methods()) {
    const BendingResult r = make_bending_method(info.name)->compute(m.topology(), m.positions(), 1.0);
    const MethodCapabilities& c = info.capabilities;
    EXPECT_EQ(r.energy.has_value(), c.has_energy) << info.name;
    EXPECT_EQ(r.normal.allFinite(), c.defines_normal) << info.name;
    EXPECT_EQ(r.H.allFinite(), c.defines_H) << info.name;
    EXPECT_EQ(r.K.allFinite(), c.defines_K) << info.name;
    EXPECT_EQ(r.lapH.allFinite(), c.defines_lapH) << info.name;
    EXPECT_TRUE(r.force.allFinite()) << info.name;
  }
}

TEST(MethodRegistry, OptionsAreCheckedAgainstTheSchema) {
  const MethodInfo& e = bending_method_info("E");
  EXPECT_EQ(resolve_method_options(e, {}), (MethodOptions{{"rings", "1"}}));
  EXPECT_EQ(resolve_method_options(e, {{"rings", "3"}}), (MethodOptions{{"rings", "3"}}));
  expect_error_naming([&] { resolve_method_options(e, {{"rings", "4"}}); }, "rings");
  expect_error_naming([&] { resolve_method_options(e, {{"rings", "two"}}); }, "rings");
  expect_error_naming([&] { resolve_method_options(e, {{"ring", "2"}}); }, "'ring'");
  expect_error_naming([] { make_bending_method("ED", {{"rings", "0"}}); }, "rings");
  expect_error_naming([] { make_bending_method("C", {{"rings", "2"}}); }, "'rings'");
  const MethodInfo& a = bending_method_info("A");
  EXPECT_EQ(resolve_method_options(a, {{"small_angle", "yes"}}).at("small_angle"), "true");
  EXPECT_EQ(resolve_method_options(a, {}).at("small_angle"), "false");
  expect_error_naming([&] { resolve_method_options(a, {{"small_angle", "maybe"}}); }, "small_angle");
  // Options given once for several methods reach only those that take them.
  EXPECT_EQ(options_for_method(bending_method_info("C"), {{"rings", "2"}}), MethodOptions{});
  EXPECT_EQ(options_for_method(e, {{"rings", "2"}, {"small_angle", "true"}}), (MethodOptions{{"rings", "2"}}));
  EXPECT_EQ(parse_option_assignment("rings=2"), (std::pair<std::string, std::string>{"rings", "2"}));
  expect_error_naming([] { parse_option_assignment("rings"); }, "key=value");
}

TEST(MethodRegistry, AMethodRegisteredFromOutsideIsListedAndMade) {
  if (!find_bending_method("registry-test-toy")) register_bending_method(toy_info());
  const std::vector<std::string> names = bending_method_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "registry-test-toy"), names.end());
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 1);
  const BendingResult c = make_bending_method("C")->compute(m.topology(), m.positions(), 1.0);
  const BendingResult t = make_bending_method("registry-test-toy", {{"scale", "2"}})->compute(
      m.topology(), m.positions(), 1.0);
  EXPECT_LT((t.force - 2.0 * c.force).cwiseAbs().maxCoeff(), 1e-15 * c.force.cwiseAbs().maxCoeff());
  expect_error_naming([] { make_bending_method("registry-test-toy", {{"scale", "11"}}); }, "scale");
  // A second registration of the name, invalid names and schemas are refused.
  expect_error_naming([] { register_bending_method(toy_info()); }, "already registered");
  MethodInfo bad = toy_info();
  bad.name = std::string("a,b");
  expect_error_naming([&] { register_bending_method(bad); }, "a,b");
  bad.name = std::string("none");
  expect_error_naming([&] { register_bending_method(bad); }, "reserved");
  bad = toy_info();
  bad.name = std::string("registry-test-bad-default");
  bad.options[0].default_value = std::string("20");
  expect_error_naming([&] { register_bending_method(bad); }, "scale");
  bad = toy_info();
  bad.name = std::string("registry-test-no-factory");
  bad.factory = nullptr;
  expect_error_naming([&] { register_bending_method(bad); }, "factory");
  EXPECT_EQ(find_bending_method("registry-test-bad-default"), nullptr);
}
