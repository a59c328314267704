#include "bendlab/mesh/mesh_spec.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <regex>

#include "bendlab/mesh/generators.hpp"
#include "bendlab/mesh/mesh_io.hpp"

namespace bendlab {

TriMesh mesh_from_spec(const std::string& spec) {
  std::smatch m;
  if (std::regex_match(spec, m, std::regex(R"((mt1|mt2|octa|irregular):(\d{1,9}))"))) {
    const MeshFamily family = parse_mesh_family(m[1]);
    const long triangles = std::stol(m[2]);
    const int level = level_with_triangles(family, triangles);
    if (level < 0 || level > 7)
      throw Error(fmt::format("--mesh {}: {} has no level with {} triangles (up to 7 steps of 4x refinement)", spec,
                              m[1].str(), triangles));
    return sphere_mesh(family, level);
  }
  if (std::regex_match(spec, m, std::regex(R"(inh:(mt1|mt2))"))) return sphere_mesh(parse_mesh_family(m[1]), 2, 3);
  std::error_code ec;
  if (!std::filesystem::exists(spec, ec))
    throw Error(fmt::format("--mesh '{}' is neither mt1:N, mt2:N, octa:N, irregular:N, inh:mt1, inh:mt2 nor an existing file", spec));
  return read_mesh(spec);
}

}  // namespace bendlab
