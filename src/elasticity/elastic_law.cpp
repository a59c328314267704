#include "bendlab/elasticity/elastic_law.hpp"

#include <fmt/format.h>

#include "bendlab/elasticity/neo_hookean.hpp"

namespace bendlab {

std::vector<std::string> elastic_law_names() { return {"neo-hookean"}; }

std::unique_ptr<ElasticLaw> make_elastic_law(const std::string& name, TopologyPtr topology, const Points& reference,
                                             double kS) {
  if (name == "neo-hookean") return std::make_unique<NeoHookean>(std::move(topology), reference, kS);
  throw Error(fmt::format("unknown elastic law '{}' (known: neo-hookean)", name));
}

}  // namespace bendlab
