// A method instance keeps buffers from call to call (method_workspace.hpp), some of them built for
// one connectivity (the per-thread neighbourhoods of E, ED and M). A topology freed and another
// built may share an address: the static study frees each mesh before it makes the next, and the
// allocator hands the same block back. Buffers keyed on the address were then reused for a larger
// mesh and written past their end (the heap corruption of `bendlab rbc` at 32768 triangles). Here
// the second topology is built in the very storage of the first, so the address is the same on
// every run, with or without the sanitizers, and the instance must give what a fresh one gives.
#include <gtest/gtest.h>

#include <memory>
#include <new>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

using namespace bendlab;

namespace {

// Storage for one Topology, so that two objects can live at the same address one after the other.
class TopologySlot {
 public:
  const Topology& emplace(const Topology& source) {
    reset();
    object_ = new (storage_) Topology(source);
    return *object_;
  }
  void reset() {
    if (object_) object_->~Topology();
    object_ = nullptr;
  }
  ~TopologySlot() { reset(); }

 private:
  alignas(Topology) unsigned char storage_[sizeof(Topology)];
  Topology* object_ = nullptr;
};

}  // namespace

TEST(TopologyIdentity, EveryObjectHasItsOwnNumber) {
  const TriMesh a = sphere_mesh(MeshFamily::Octa, 1);
  const TriMesh b = sphere_mesh(MeshFamily::Octa, 1);
  EXPECT_NE(a.topology().id(), b.topology().id());
  TopologySlot slot;
  const std::uint64_t first = slot.emplace(a.topology()).id();
  EXPECT_NE(first, a.topology().id());  // a copy is another object
  const std::uint64_t second = slot.emplace(a.topology()).id();
  EXPECT_NE(first, second);  // same address, another object
}

TEST(WorkspaceReuse, EveryMethodGivesAFreshInstancesResultOnATopologyAtAFreedOnesAddress) {
  // The octahedral RBC, a coarse mesh then a finer one (more vertices: a buffer of the coarse one
  // indexed by the fine one's vertices overflows), as the study orders them.
  const auto rbc = make_rbc();
  const TriMesh coarse = sphere_mesh(MeshFamily::Octa, 3);
  const TriMesh fine = sphere_mesh(MeshFamily::Octa, 4);
  const Points x_coarse = rbc->map_from_unit_sphere(coarse.positions());
  const Points x_fine = rbc->map_from_unit_sphere(fine.positions());
  for (const MethodInfo& info : bending_methods()) {
    SCOPED_TRACE(info.name);
    const std::unique_ptr<BendingMethod> kept = make_bending_method(info.name, {});
    TopologySlot slot;
    kept->compute(slot.emplace(coarse.topology()), x_coarse, 1.0);
    const Topology& t = slot.emplace(fine.topology());
    const BendingResult reused = kept->compute(t, x_fine, 1.0);
    const BendingResult fresh = make_bending_method(info.name, {})->compute(fine.topology(), x_fine, 1.0);
    ASSERT_EQ(reused.force.rows(), fine.num_vertices());
    EXPECT_EQ(reused.force, fresh.force);
    EXPECT_EQ(reused.area, fresh.area);
  }
}
