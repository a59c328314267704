// bendlab: membrane bending forces on triangulated surfaces, and capsules in flow.
// Started by mpirun or srun (in a build with BENDLAB_MPI), every rank runs the same command: MPI
// is initialised here, and only rank 0 prints notes and progress. An error every rank met alike
// is one line from rank 0 and a normal end of every rank; an error on some ranks prints its
// message (naming the rank) and ends every rank with MPI_Abort (docs/mpi.md).
#include <fmt/format.h>

#include <charconv>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <iostream>
#include <limits>
#include <set>
#include <string>
#include <thread>
#ifdef BENDLAB_HAVE_MPI
#include <mpi.h>
#endif

#include "bendlab/core/types.hpp"
#include "command.hpp"

namespace bendlab::cli {

std::vector<CommandSetup>& command_registry() {
  static std::vector<CommandSetup> registry;
  return registry;
}

namespace {
ProcessWorld& world() {
  static ProcessWorld w;
  return w;
}
}  // namespace

const ProcessWorld& process_world() { return world(); }

void note(const std::string& message) {
  if (world().rank == 0) std::cerr << message << std::endl;
}

}  // namespace bendlab::cli

namespace {

#ifdef BENDLAB_HAVE_MPI
// Whether a process launcher started this process as one of a parallel job (Open MPI's mpirun,
// PMI/PMIx launchers such as srun). A plain `bendlab ...` does not initialise MPI.
bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(v) != nullptr) return true;
  return false;
}
#endif

// An unsigned option (a seed) is decimal digits within 0 ... 2^64 - 1. CLI11 alone takes "-1",
// "1e23" and "18446744073709551616" all for 2^64 - 1.
std::string whole_number_error(const std::string& value) {
  std::uint64_t v = 0;
  const char* end = value.data() + value.size();
  const auto [stop, ec] = std::from_chars(value.data(), end, v);
  if (ec == std::errc::invalid_argument || stop != end)
    return fmt::format("'{}' is not a whole number from 0 to {}", value, std::numeric_limits<std::uint64_t>::max());
  if (ec == std::errc::result_out_of_range)
    return fmt::format("{} is above the largest value, {}", value, std::numeric_limits<std::uint64_t>::max());
  return {};
}

// CLI11 converts an empty value of a numeric option ("--level ''") to 0: every number option of
// every subcommand refuses one instead, before the conversion; an unsigned one takes a whole
// number in range only.
void refuse_empty_numbers(CLI::App& app) {
  static const std::set<std::string> numeric = {"INT", "UINT", "FLOAT", "NUMBER"};
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    for (CLI::Option* opt : sub->get_options([](CLI::Option*) { return true; })) {
      if (numeric.count(opt->get_type_name()) > 0)
        opt->check(CLI::Validator(
            [](std::string& value) { return value.empty() ? std::string("'' is not a number") : std::string(); },
            "", "not empty"));
      if (opt->get_type_name() == "UINT")
        opt->check(CLI::Validator([](std::string& value) { return whole_number_error(value); }, "", "whole number"));
    }
    refuse_empty_numbers(*sub);
  }
}

struct MpiSession {
  bool active = false;
  MpiSession(int& argc, char**& argv) {
#ifdef BENDLAB_HAVE_MPI
    if (!launched_by_mpi()) return;
    MPI_Init(&argc, &argv);
    active = true;
    auto& w = bendlab::cli::world();
    MPI_Comm_rank(MPI_COMM_WORLD, &w.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &w.size);
#else
    (void)argc;
    (void)argv;
#endif
  }
  ~MpiSession() {
#ifdef BENDLAB_HAVE_MPI
    if (active) MPI_Finalize();
#endif
  }
  // Whether every rank reached this call within a few seconds: an error that every rank met alike
  // (the checks of the options and files, which run on every rank before any collective work).
  // A rank waiting in a collective call of the work never arrives, and this returns false.
  bool all_ranks_failed() {
#ifdef BENDLAB_HAVE_MPI
    if (!active) return false;
    MPI_Request request;
    MPI_Ibarrier(MPI_COMM_WORLD, &request);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    int done = 0;
    while (!done && std::chrono::steady_clock::now() < deadline) {
      MPI_Test(&request, &done, MPI_STATUS_IGNORE);
      if (!done) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return done != 0;
#else
    return false;
#endif
  }
  // An error on one rank: the others may wait in a collective call, so every rank is ended.
  [[noreturn]] void abort_all(int code) {
#ifdef BENDLAB_HAVE_MPI
    if (active) MPI_Abort(MPI_COMM_WORLD, code);
#endif
    std::exit(code);
  }
};

}  // namespace

int main(int argc, char** argv) {
  MpiSession mpi(argc, argv);
  const auto& world = bendlab::cli::process_world();
  const std::string who = world.size > 1 ? fmt::format("bendlab (rank {} of {})", world.rank, world.size) : "bendlab";
  CLI::App app{"bendlab: membrane bending forces on triangulated surfaces, checked against exact "
               "analytic results, and elastic capsules in shear flow"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "bendlab 0.1.0");
  for (auto& setup : bendlab::cli::command_registry()) setup(app);
  refuse_empty_numbers(app);
  // A write beyond the file size limit (ulimit -f) then fails with EFBIG, which every writer
  // reports as a write error naming the file (removing its temporary), instead of the signal
  // ending the process and leaving the temporary behind.
  std::signal(SIGXFSZ, SIG_IGN);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return world.rank == 0 ? app.exit(e) : 0;  // --help, --version
    // A usage error: one line naming the problem, as for every other error. Every rank parses
    // the same arguments, so every rank ends here alike.
    if (world.rank == 0) std::cerr << "bendlab: error: " << e.what() << " (see --help)" << std::endl;
    return e.get_exit_code();
  } catch (const std::exception& e) {
    // Commands do their work in callbacks, which run inside parse(). An error every rank met
    // alike is said once, by rank 0, and every rank ends normally; an error of some ranks names
    // the rank and ends them all. One write per line, so that the ranks' lines do not interleave.
    if (world.size > 1 && mpi.all_ranks_failed()) {
      if (world.rank == 0) std::fputs(fmt::format("bendlab: error: {}\n", e.what()).c_str(), stderr);
      return 1;
    }
    const std::string line = fmt::format("{}: error: {}\n", who, e.what());
    std::fputs(line.c_str(), stderr);
    std::fflush(stderr);
    if (world.size > 1) mpi.abort_all(1);
    return 1;
  }
  return 0;
}
