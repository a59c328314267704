// bendlab rbc: the static red-blood-cell benchmark of the paper's section 3 (tables 2 and 3,
// figures 3-10, B.19-B.23): errors of every method against the exact RBC, their convergence,
// per-node values for the plots, VTK files of the per-node errors, and the plots.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <filesystem>
#include <optional>

#include "bendlab/analysis/rbc_report.hpp"
#include "bendlab/analysis/rbc_study.hpp"
#include "bendlab/core/helper_program.hpp"
#include "cli_common.hpp"
#include "method_cli.hpp"
#include "command.hpp"

namespace bendlab::cli {
namespace {

namespace fs = std::filesystem;

struct RbcArgs {
  std::vector<std::string> families = {"mt1", "mt2", "octa", "inhomogeneous", "irregular"};
  std::vector<std::string> methods = bending_method_names();
  int max_triangles = 81920;  // the paper's largest meshes; the whole study takes a few minutes
  std::optional<int> rings;  // none: the methods' default
  std::string base = "default";
  double jitter = kDefaultJitterFraction;
  std::uint64_t jitter_seed = kDefaultJitterSeed;
  std::string out;
  bool plots = true;
  std::string plot_script;
  std::string python = "/usr/bin/python3";
  MembraneTermArgs terms;
  bool methods_given = false;
};

// Fails early, with a one-line message, when files cannot be created in dir.
void require_writable_dir(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw Error(fmt::format("--out '{}': cannot create the folder ({})", dir.string(),
                            ec ? ec.message() : "not a folder"));
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw Error(fmt::format("--out '{}': the folder is not writable", dir.string()));
}

void run_rbc(const RbcArgs& a) {
  RbcStudyOptions o;
  o.families = a.families;
  o.methods = a.methods;
  o.max_triangles = a.max_triangles;
  o.base = a.base;
  o.jitter = a.jitter;
  o.jitter_seed = a.jitter_seed;
  // c0 / ADE (docs/conventions.md §5); A is the exact area of the RBC (refused if given).
  if (a.terms.ade_area) throw Error("--ade-area: rbc uses the exact area of the analytic RBC");
  const BendingParameters params = membrane_parameters(o.kappa_b, a.terms, 1.0);
  o.c0 = params.c0;
  o.ade_alpha = params.ade_alpha;
  o.ade_d = params.ade_d;
  o.ade_da0 = params.ade_da0;
  if (!params.plain() && !a.methods_given) {
    // The default list: the methods that take c0 and ADE (A does not, §5).
    std::vector<std::string> keep;
    for (const std::string& m : o.methods) {
      try {
        make_bending_method(m)->check_parameters(params);
        keep.push_back(m);
      } catch (const Error& e) {
        note(fmt::format("rbc: method {} left out: {}", m, e.what()));
      }
    }
    o.methods = keep;
  }
  if (a.rings) {
    if (*a.rings < 1 || *a.rings > 3) throw Error(fmt::format("--rings must be 1, 2 or 3, got {}", *a.rings));
    o.method_options["rings"] = std::to_string(*a.rings);
  }
  validate(o);
  if (a.out.empty()) throw Error("--out: no output folder given");
  const fs::path out = a.out;
  require_writable_dir(out);
  fs::path script;
  if (a.plots) {
    script = find_helper_script("plot_rbc.py", a.plot_script);
    if (script.empty() || !fs::is_regular_file(script))
      throw Error("--plot-script: scripts/plot_rbc.py not found near the executable or the current folder "
                  "(give --plot-script PATH, or --no-plots)");
  }

  o.progress = [](const std::string& line) { note(line); };
  const RbcStudyResult s = run_rbc_study(o);
  write_rbc_report(out, s);
  note(fmt::format("rbc: wrote errors.csv, errors.json, timings.csv, table2.md, table3.md and values_*.csv to {}",
                   out.string()));

  if (a.plots) {
    const std::vector<std::string> argv = {a.python, script.string(), out.string()};
    note(fmt::format("rbc: {}", fmt::join(argv, " ")));
    // A plot not made is a warning (README, "Errors"), whether the interpreter ran and failed or
    // could not start at all: the data files are the results.
    try {
      const int status = run_helper_program(argv);
      if (status != 0)
        note(fmt::format("warning: the plots were not made ({} exited with status {}); the data files in {} are "
                         "complete",
                         a.python, status, out.string()));
    } catch (const Error& e) {
      note(fmt::format("warning: the plots were not made ({}); the data files in {} are complete", e.what(),
                       out.string()));
    }
  }
}

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> items;
  std::string cur;
  for (char c : s + ",") {
    if (c == ',') {
      if (!cur.empty()) items.push_back(cur);
      cur.clear();
    } else if (c != ' ') {
      cur += c;
    }
  }
  return items;
}

const CommandRegistration rbc_registration([](CLI::App& app) {
  auto args = std::make_shared<RbcArgs>();
  auto families = std::make_shared<std::string>("mt1,mt2,octa,inhomogeneous,irregular");
  auto methods = std::make_shared<std::string>(method_names_joined(","));
  auto* cmd = app.add_subcommand(
      "rbc",
      "Static RBC benchmark (paper section 3): errors of each method against the exact red blood cell "
      "for the mesh families, convergence tables 2 and 3, per-node values and plots. Writes to --out: "
      "errors.csv (family,triangles,h,method,quantity,max_error,avg_error), errors.json (the same rows, "
      "timings, fitted slopes, table cells), timings.csv, values_<family>_<triangles>.csv (per node: theta, "
      "numerical and exact H, K, Lap H, |f|, errors; meshes up to 5120 triangles and the inhomogeneous "
      "ones), errors_<family>_5120_<method>.vtp (per-node errors, MT1 and MT2), table2.md, table3.md and "
      "the PNG plots");
  cmd->add_option("--families", *families,
                  "comma-separated mesh families: mt1 (Loop), mt2 (midpoint), octa (octahedron: 512, 2048, ...), "
                  "inhomogeneous (320-triangle MT1 and MT2 spheres + 3 Rivara passes; always run in full), "
                  "irregular (MT1 with every node jittered, see --jitter: 320, 1280, ...)")
      ->capture_default_str();
  cmd->add_option("--max-triangles", args->max_triangles,
                  "largest homogeneous mesh, at least 320 (320, 1280, 5120, 20480, 81920 for MT1/MT2)")
      ->capture_default_str();
  cmd->add_option("--methods", *methods, "comma-separated bending methods among " + method_names_joined())
      ->capture_default_str();
  cmd->add_option("--rings", args->rings, "neighbour rings of the fits of Methods E and ED (1, 2 or 3; "
                                          "default: the methods' own default)");
  cmd->add_option("--base", args->base,
                  "icosahedron of MT1/MT2: default (vertices at (+-1, +-phi, 0), four on the rim) or polar "
                  "(a vertex at each pole)")
      ->check(CLI::IsMember({"default", "polar"}))
      ->capture_default_str();
  cmd->add_option("--jitter", args->jitter,
                  "irregular family: every node of the MT1 sphere moves in its tangent plane by this fraction of "
                  "the mean length of its edges, in a random direction, and is projected back onto the sphere "
                  "(bendlab mesh --help); a fraction that folds a triangle of any of the study's irregular meshes "
                  "is refused before any work")
      ->capture_default_str();
  cmd->add_option("--jitter-seed", args->jitter_seed, "irregular family: base seed; level k uses seed (base + k)")
      ->capture_default_str();
  add_membrane_term_options(cmd, args->terms, false,
                            " (lengths in units of R: c0 R, d / R, dA0 / R^2; the exact f is the force law of "
                            "docs/conventions.md §5 from the exact H, K, Lap H, and ADE's A and M are the exact RBC's; "
                            "without --methods, methods that refuse c0/ADE are left out)");
  cmd->add_option("--out", args->out, "output folder (created if missing)")->required();
  cmd->add_flag("--plots,!--no-plots", args->plots, "run scripts/plot_rbc.py on the output to draw the PNG plots "
                                                   "(default: on)");
  cmd->add_option("--plot-script", args->plot_script,
                  "path of plot_rbc.py (default: share/bendlab/scripts/ of an installed bendlab, or scripts/ "
                  "found in or above the executable's folder or the current folder)");
  cmd->add_option("--python", args->python, "Python interpreter with numpy and matplotlib")->capture_default_str();
  auto* methods_option = cmd->get_option("--methods");
  cmd->callback([args, families, methods, methods_option] {
    args->methods_given = methods_option->count() > 0;
    args->families = split_list(*families);
    args->methods = split_list(*methods);
    run_rbc(*args);
  });
});

}  // namespace
}  // namespace bendlab::cli
