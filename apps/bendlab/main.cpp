// bendlab: membrane bending forces on triangulated surfaces, and capsules in flow.
#include <iostream>

#include "bendlab/core/types.hpp"
#include "command.hpp"

namespace bendlab::cli {

std::vector<CommandSetup>& command_registry() {
  static std::vector<CommandSetup> registry;
  return registry;
}

void note(const std::string& message) { std::cerr << message << std::endl; }

}  // namespace bendlab::cli

int main(int argc, char** argv) {
  CLI::App app{"bendlab: membrane bending forces on triangulated surfaces, checked against exact "
               "analytic results, and elastic capsules in shear flow"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "bendlab 0.1.0");
  for (auto& setup : bendlab::cli::command_registry()) setup(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // A usage error: one line naming the problem, as for every other error.
    std::cerr << "bendlab: error: " << e.what() << " (see --help)" << std::endl;
    return e.get_exit_code();
  } catch (const std::exception& e) {
    // Commands do their work in callbacks, which run inside parse().
    std::cerr << "bendlab: error: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
