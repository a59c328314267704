#pragma once
// Scratch memory a bending method keeps from call to call (its "workspace"), so that a time loop
// evaluating the same method on the same mesh allocates nothing once warm.
//
// Why it matters more than the allocation itself: the arrays of one evaluation at 81920 triangles
// are megabytes each. glibc serves such blocks from the top of its heap (or from mmap) and hands
// them back to the kernel when they are freed (heap trimming above M_TRIM_THRESHOLD, munmap), so
// the next call faults every page in again, zero-filled by the kernel: about 3100 page faults of
// 14-17 us each per call of Method C on the 2-core reference machine, 5 to 6 times the
// arithmetic. Whether glibc trims depends on what else lies on the heap, so a method's time
// depended on the methods run before it (docs/benchmarks.md, "Order of the methods").
//
// A workspace is per method instance: the instance owns it, and sizes it to the mesh of the last
// call (std::vector and Eigen keep their storage when resized to the same size). "Warm" is after
// two calls on the mesh: some arrays change places with the caller's result instead of being
// copied (the geometry's normals and areas), so each side owns its own from the second call on. Concurrent calls
// on one instance stay correct: the first caller holds the kept workspace, a second one gets a
// fresh workspace for its call (allocated and freed, as before workspaces were kept). A copy of a
// method starts with an empty workspace. T may be incomplete where the holder is declared (a
// method's private struct, defined in its .cpp): the kept T is created on the first call, so the
// holder's destructor must be defined where T is complete.
#include <memory>
#include <mutex>

namespace bendlab {

template <class T>
class MethodWorkspace {
 public:
  MethodWorkspace() = default;
  MethodWorkspace(const MethodWorkspace&) {}
  MethodWorkspace& operator=(const MethodWorkspace&) { return *this; }

  /// The workspace for one call: the kept one, locked until the lease ends, or a fresh one.
  class Lease {
   public:
    T& operator*() const { return *ws_; }
    T* operator->() const { return ws_; }
    /// Whether this is the kept workspace (false: a fresh one for a concurrent call).
    bool kept() const { return lock_.owns_lock(); }

   private:
    friend class MethodWorkspace;
    std::unique_lock<std::mutex> lock_;
    std::unique_ptr<T> own_;
    T* ws_ = nullptr;
  };

  Lease acquire() const {
    Lease lease;
    lease.lock_ = std::unique_lock<std::mutex>(mutex_, std::try_to_lock);
    if (lease.lock_.owns_lock()) {
      if (!kept_) kept_ = std::make_unique<T>();
      lease.ws_ = kept_.get();
    } else {
      lease.own_ = std::make_unique<T>();
      lease.ws_ = lease.own_.get();
    }
    return lease;
  }

 private:
  mutable std::mutex mutex_;
  mutable std::unique_ptr<T> kept_;
};

}  // namespace bendlab
