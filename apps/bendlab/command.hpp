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

/// Progress and notes go to stderr, so that stdout stays machine-readable (JSON, CSV).
void note(const std::string& message);

}  // namespace bendlab::cli
