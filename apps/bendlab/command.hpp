#pragma once
// Subcommands register themselves: each apps/bendlab/<name>_command.cpp defines one
// `static CommandRegistration` that adds its CLI11 subcommand and callback.
#include <CLI/CLI.hpp>
#include <functional>
#include <vector>

namespace bendlab::cli {

using CommandSetup = std::function<void(CLI::App& app)>;

std::vector<CommandSetup>& command_registry();

struct CommandRegistration {
  explicit CommandRegistration(CommandSetup setup) { command_registry().push_back(std::move(setup)); }
};

/// Progress and notes go to stderr, so that stdout stays machine-readable (JSON, CSV). Under
/// mpirun only rank 0 prints them.
void note(const std::string& message);

/// The MPI world of this process: rank 0 of 1 unless started by mpirun/srun in a build with
/// BENDLAB_MPI (main.cpp initialises MPI then).
struct ProcessWorld {
  int rank = 0, size = 1;
};
const ProcessWorld& process_world();

}  // namespace bendlab::cli
