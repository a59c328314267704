// libFuzzer target: the mesh readers (mesh/mesh_io.hpp). The first byte picks the format (OFF,
// OBJ, PLY), the rest is the file; what parses is also validated as a TriMesh. Any input is
// accepted or refused with bendlab::Error; anything else aborts (fuzz/README.md).
#include <cstddef>
#include <cstdint>
#include <string>

#include "bendlab/mesh/mesh_io.hpp"
#include "bendlab/mesh/trimesh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* const kFormats[] = {"off", "obj", "ply"};
  const std::string format = kFormats[data[0] % 3];
  try {
    bendlab::RawMesh raw =
        bendlab::parse_raw_mesh(std::string(reinterpret_cast<const char*>(data + 1), size - 1), format, "fuzz." + format);
    bendlab::TriMesh mesh(std::move(raw.positions), raw.faces);
  } catch (const bendlab::Error&) {
  }
  return 0;
}
