#include "bendlab/elasticity/elastic_law.hpp"

#include <fmt/format.h>

#include "bendlab/elasticity/neo_hookean.hpp"
#include "bendlab/elasticity/skalak.hpp"

namespace bendlab {

std::vector<std::string> elastic_law_names() { return {"neo-hookean", "skalak"}; }

std::unique_ptr<ElasticLaw> make_elastic_law(const std::string& name, TopologyPtr topology, const Points& reference,
                                             double kS, double skalak_c) {
  if (name == "neo-hookean") return std::make_unique<NeoHookean>(std::move(topology), reference, kS);
  if (name == "skalak") return std::make_unique<Skalak>(std::move(topology), reference, kS, skalak_c);
  throw Error(fmt::format("unknown elastic law '{}' (known: neo-hookean, skalak)", name));
}

}  // namespace bendlab
