// libFuzzer target: the capsule checkpoint reader (capsule/checkpoint.hpp) for a 42-vertex mesh
// (the 80-triangle MT1 sphere). Any input is accepted or refused with bendlab::Error; anything else
// aborts (fuzz/README.md).
#include <cstddef>
#include <cstdint>
#include <string>

#include "bendlab/capsule/checkpoint.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)bendlab::CapsuleCheckpoint::parse(std::string(reinterpret_cast<const char*>(data), size), 42,
                                            "fuzz.json");
  } catch (const bendlab::Error&) {
  }
  return 0;
}
