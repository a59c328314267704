// libFuzzer target: the time-series CSV reader (capsule/time_series.hpp). Any input is accepted
// or refused with bendlab::Error; anything else aborts (fuzz/README.md).
#include <cstddef>
#include <cstdint>
#include <string>

#include "bendlab/capsule/time_series.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)bendlab::parse_time_series(std::string(reinterpret_cast<const char*>(data), size), "fuzz.csv");
  } catch (const bendlab::Error&) {
  }
  return 0;
}
