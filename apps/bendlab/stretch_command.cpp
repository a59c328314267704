// bendlab stretch: optical-tweezers stretching of a red blood cell in physical units (Mills et al.
// 2004; shared/spec/CELLS_IN_CHANNELS.md section 5): the equilibrium shape under a list of forces,
// its axial and transverse diameters, and a plot against the experiment. Argument parsing, the run
// folder and the files only: the physics is OpticalStretch (bendlab/flow/optical_stretch.hpp).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cerrno>
#include <cmath>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <regex>

#include "bendlab/core/atomic_file.hpp"
#include "bendlab/core/folder_lock.hpp"
#include "bendlab/core/helper_program.hpp"
#include "bendlab/core/output_folder.hpp"
#include "bendlab/flow/optical_stretch.hpp"
#include "bendlab/mesh/mesh_io.hpp"
#include "command.hpp"
#include "method_cli.hpp"

namespace bendlab::cli {
namespace {

namespace fs = std::filesystem;

struct StretchArgs {
  std::string out;
  std::string forces = "0,25,50,75,100,125,150,175,193";
  bool overwrite = false;
  bool plots = true;
  std::string plot_script;
  std::string python = "/usr/bin/python3";
  std::vector<std::string> options;
  StretchSpec spec;
};

// The files a stretch run writes (and AtomicFile's temporaries of them): the only files
// --overwrite removes.
bool is_stretch_output(const std::string& name) {
  static const std::regex shape_re(R"(shape_\d{3,}\.vtp)");
  return name == "stretch.csv" || name == "summary.json" || name == "shapes.pvd" || name == "stretch.png" ||
         std::regex_match(name, shape_re);
}
bool is_stretch_file(const std::string& name) {
  if (is_stretch_output(name)) return true;
  const std::optional<std::string> target = atomic_temp_target(name);
  return target && is_stretch_output(*target);
}

// A new folder, or an existing one: refused when it holds anything (but a lock file) unless
// --overwrite, which removes the files of an earlier stretch run and nothing else.
void prepare_folder(const fs::path& out, bool overwrite) {
  if (out.empty()) throw Error("--out: no output folder given");
  const fs::path parent = parent_folder(out);
  if (!fs::is_directory(parent))
    throw Error(fmt::format("--out '{}': folder '{}' does not exist", out.string(), parent.string()));
  if (fs::exists(out) && !fs::is_directory(out))
    throw Error(fmt::format("--out '{}' exists and is not a folder", out.string()));
  if (!fs::exists(out)) return;
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    if (name != FolderLock::file_name()) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  if (!names.empty() && !overwrite)
    throw Error(fmt::format("--out '{}' is not empty (it holds '{}'{}); use another folder, or --overwrite to replace "
                            "an earlier stretch run's files",
                            out.string(), names.front(),
                            names.size() > 1 ? fmt::format(" and {} more", names.size() - 1) : std::string()));
}

void clear_old_run(const fs::path& out) {
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() || !is_stretch_file(name)) continue;
    std::error_code ec;
    fs::remove(entry.path(), ec);
    if (ec) throw Error(fmt::format("cannot remove '{}': {}", entry.path().string(), ec.message()));
  }
}

void write_csv(const fs::path& path, const std::vector<StretchPoint>& points) {
  AtomicFile f(path);
  std::ostream& o = f.stream();
  o << "force_pN,axial_diameter_um,transverse_diameter_um,iterations,residual_pN,area_change,volume_change,"
       "converged,extent_y_um,extent_z_um\n";
  // A number that is not finite (a relaxation that failed) is written as an empty field, as in
  // every result file of bendlab: undefined, never "inf" or "nan".
  auto number = [](double v) { return std::isfinite(v) ? fmt::format("{:.17g}", v) : std::string(); };
  for (const StretchPoint& p : points)
    o << fmt::format("{},{},{},{},{},{},{},{},{},{}\n", number(p.force_pN), number(p.measures.axial_um),
                     number(p.measures.transverse_um), p.iterations, number(p.residual_pN), number(p.area_change),
                     number(p.volume_change), p.converged ? 1 : 0, number(p.measures.extent_y_um),
                     number(p.measures.extent_z_um));
  f.commit();
}

void write_json(const fs::path& path, const nlohmann::json& j) {
  AtomicFile f(path);
  f.stream() << j.dump(2) << '\n';
  f.commit();
}

void run_plot(const StretchArgs& a, const fs::path& out) {
  const fs::path script = find_helper_script("plot_stretch.py", a.plot_script);
  if (script.empty() || !fs::is_regular_file(script)) {
    note("warning: the plot was not made (scripts/plot_stretch.py not found; give --plot-script PATH); the data files "
         "in " + out.string() + " are complete");
    return;
  }
  const std::vector<std::string> argv = {a.python, script.string(), out.string()};
  note(fmt::format("stretch: {}", fmt::join(argv, " ")));
  // A plot not made is a warning (README, "Errors"): the data files are the results.
  try {
    const int status = run_helper_program(argv);
    if (status != 0)
      note(fmt::format("warning: the plot was not made ({} exited with status {}); the data files in {} are complete",
                       a.python, status, out.string()));
  } catch (const Error& e) {
    note(fmt::format("warning: the plot was not made ({}); the data files in {} are complete", e.what(),
                     out.string()));
  }
}

// --forces: numbers separated by single commas. Every entry counts: "1,,2", "1,2," and ",1" are
// refused (a list split by CLI11 drops empty entries without a word).
std::vector<double> parse_forces(const std::string& text) {
  std::vector<double> forces;
  std::size_t begin = 0;
  for (int k = 1;; ++k) {
    const std::size_t comma = text.find(',', begin);
    const std::string entry = text.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    if (entry.empty())
      throw Error(fmt::format("--forces '{}': entry {} is empty (give forces in pN separated by single commas)", text, k));
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(entry.c_str(), &end);
    if (end != entry.c_str() + entry.size() || errno == ERANGE)
      throw Error(fmt::format("--forces '{}': entry {} '{}' is not a number of pN", text, k, entry));
    forces.push_back(value);
    if (comma == std::string::npos) return forces;
    begin = comma + 1;
  }
}

void stretch(StretchArgs& a) {
  StretchSpec& s = a.spec;
  s.forces_pN = parse_forces(a.forces);
  s.cell.method_options = a.options;
  if (s.cell.bending_modulus > 0 && s.cell.method == "none")
    throw Error("--method none needs --bending-modulus 0");
  // Every check before the folder is touched: the spec, the mesh, the method and its options, the
  // pulled vertices (the constructor builds them all).
  OpticalStretch run(s);
  const fs::path out = a.out;
  prepare_folder(out, a.overwrite);
  if (!fs::exists(out)) {
    std::error_code ec;
    fs::create_directory(out, ec);
    if (ec && !fs::is_directory(out))
      throw Error(fmt::format("--out '{}': cannot create the folder ({})", out.string(), ec.message()));
  }
  FolderLock lock(out, "run folder");
  if (a.overwrite) clear_old_run(out);

  const CellKind& kind = run.cell();
  const int n = kind.reference_um.num_vertices();
  const StretchMeasures& ref = run.reference_measures();
  note(fmt::format("stretch: {} {} ({} vertices, mean edge {:.3g} um), {} law, G_s = {:g} N/m, kappa_B = {:g} J, "
                   "method {}; {} vertices pulled at each end; tolerance {:g} pN; {} relaxation",
                   kind.spec.shape, kind.spec.mesh, n, kind.mean_edge_um, kind.spec.elastic_law, kind.spec.shear_modulus,
                   kind.spec.bending_modulus, kind.spec.method, run.right_vertices().size(), s.tolerance_pN,
                   to_string(run.spec().relaxation)));
  note(fmt::format("stretch: reference shape: axial {:.4f} um, transverse {:.4f} um, area {:.4g} um^2, volume {:.4g} "
                   "um^3",
                   ref.axial_um, ref.transverse_um, ref.area_um2, ref.volume_um3));

  const auto start = std::chrono::steady_clock::now();
  auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  std::vector<StretchPoint> points;
  std::vector<std::pair<double, std::string>> shapes;
  nlohmann::json summary = run.spec().to_json();  // the relaxation resolved from auto
  summary["command"] = "stretch";
  summary["vertices"] = n;
  summary["pulled_vertices"] = run.right_vertices().size();
  summary["mean_edge_um"] = kind.mean_edge_um;
  summary["reference"] = {{"axial_diameter_um", ref.axial_um},   {"transverse_diameter_um", ref.transverse_um},
                          {"extent_y_um", ref.extent_y_um},      {"extent_z_um", ref.extent_z_um},
                          {"area_um2", ref.area_um2},            {"volume_um3", ref.volume_um3}};
  std::optional<StretchPoint> failed;
  for (std::size_t k = 0; k < s.forces_pN.size(); ++k) {
    const double t0 = seconds();
    const StretchPoint p = run.equilibrate(s.forces_pN[k], [](const std::string& line) { note(line); });
    points.push_back(p);
    const std::string name = fmt::format("shape_{:03d}.vtp", k);
    VertexFields fields;
    fields.vectors.push_back({"membrane_force", run.membrane_force()});
    fields.vectors.push_back({"applied_force", run.applied_forces(p.force_pN)});
    write_mesh(out / name, run.membrane().topology(), run.positions(), fields);
    shapes.push_back({p.force_pN, name});
    write_pvd(out / "shapes.pvd", shapes);
    write_csv(out / "stretch.csv", points);
    note(fmt::format("F = {:g} pN: axial {:.4f} um, transverse {:.4f} um, {} iterations, residual {:.3g} pN, area "
                     "{:+.2e}, volume {:+.2e}, {:.1f} s{}",
                     p.force_pN, p.measures.axial_um, p.measures.transverse_um, p.iterations, p.residual_pN,
                     p.area_change, p.volume_change, seconds() - t0, p.converged ? "" : "  NOT CONVERGED"));
    if (!p.converged) {
      failed = p;
      break;
    }
  }
  nlohmann::json rows = nlohmann::json::array();
  for (const StretchPoint& p : points) rows.push_back(p.to_json());
  summary["points"] = rows;
  summary["converged"] = !failed.has_value();
  summary["failed_at_pN"] = failed ? nlohmann::json(failed->force_pN) : nlohmann::json(nullptr);
  long total = 0;
  for (const StretchPoint& p : points) total += p.iterations;
  summary["iterations"] = total;
  summary["wall_seconds"] = seconds();
  write_json(out / "summary.json", summary);
  if (failed)
    throw Error(fmt::format("stretch: F = {:g} pN did not reach equilibrium: {} (--max-iterations, --tolerance); the "
                            "forces before it are in {}",
                            failed->force_pN, failed->failure, out.string()));
  if (a.plots) run_plot(a, out);
  std::cout << fmt::format("{{\"converged\": true, \"forces\": {}, \"iterations\": {}, \"wall_seconds\": {:.3f}}}",
                           points.size(), total, seconds())
            << std::endl;
}

const CommandRegistration stretch_registration([](CLI::App& app) {
  auto args = std::make_shared<StretchArgs>();
  StretchSpec& s = args->spec;
  auto* cmd = app.add_subcommand(
      "stretch",
      "Optical-tweezers stretching of a red blood cell in physical units (Mills et al. 2004): a total force F pulls "
      "the --fraction of the vertices with the largest x along +x and as many with the smallest x along -x; the "
      "equilibrium at each force (relaxation by --relaxation until the largest nodal residual |F_membrane + F_applied| is below "
      "--tolerance, each force starting from the previous equilibrium). Writes to --out: stretch.csv (force_pN, "
      "axial_diameter_um = extent along x, transverse_diameter_um = the largest width across x, i.e. the largest "
      "distance between two vertices projected onto the y-z plane, iterations, residual_pN, area_change = A/A0 - 1, "
      "volume_change = V/V0 - 1, converged, extent_y_um, extent_z_um), summary.json, shape_NNN.vtp per force (with "
      "the membrane and applied forces), shapes.pvd and stretch.png (against the experiment). The defaults are "
      "bendlab flow's red blood cell (docs/conventions.md §6-7)");
  cmd->add_option("--forces", args->forces, "comma-separated total forces at each end, pN (>= 0), run in this order")
      ->capture_default_str();
  cmd->add_option("--fraction", s.fraction,
                  "fraction of the vertices pulled at each end, in (0, 0.5]: round(fraction N) vertices")
      ->capture_default_str();
  cmd->add_option("--tolerance", s.tolerance_pN,
                  "equilibrium: the largest nodal residual |F_membrane + F_applied|, pN")
      ->capture_default_str();
  cmd->add_option("--max-iterations", s.max_iterations, "relaxation steps per force before the run fails")
      ->capture_default_str();
  cmd->add_option("--relaxation", s.relaxation,
                  "how equilibrium is sought: fire (FIRE, inertial: for forces that are an energy's gradient or "
                  "nearly), overdamped (dx/dt = residual, as a cell in Stokes flow, with Anderson mixing: for forces "
                  "whose Jacobians are far from symmetric), or auto: overdamped for M, fire otherwise")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, StretchRelaxation>{{"auto", StretchRelaxation::Auto},
                                                   {"fire", StretchRelaxation::Fire},
                                                   {"overdamped", StretchRelaxation::Overdamped}},
          CLI::ignore_case))
      ->option_text("TEXT:{auto,fire,overdamped}=auto");
  cmd->add_option("--cell", s.cell.shape, "cell kind: rbc (eq. (15) of the paper) or sphere")
      ->check(CLI::IsMember({"rbc", "sphere"}))
      ->capture_default_str();
  cmd->add_option("--cell-radius", s.cell.radius_um, "cell radius R, um (rbc: the large half-axis)")
      ->capture_default_str();
  cmd->add_option("--mesh", s.cell.mesh, "cell mesh: mt1:N or mt2:N (N triangles) or a mesh file")
      ->capture_default_str();
  cmd->add_option("--method", s.cell.method, "bending method: " + method_choices_help() +
                                                 "; none needs --bending-modulus 0")
      ->check(CLI::IsMember(method_choices_with_none()))
      ->capture_default_str();
  cmd->add_option("--option", args->options, "method option key=value, repeatable (bendlab methods)");
  cmd->add_option("--law,--membrane", s.cell.elastic_law, "in-plane elastic law: skalak or neo-hookean")
      ->check(CLI::IsMember({"skalak", "neo-hookean"}))
      ->capture_default_str();
  cmd->add_option("--shear-modulus", s.cell.shear_modulus, "membrane shear modulus G_s, N/m (k_S = 3 G_s)")
      ->capture_default_str();
  cmd->add_option("--skalak-c", s.cell.skalak_c, "the Skalak law's C (area modulus G_s (1 + 2C))")
      ->capture_default_str();
  cmd->add_option("--bending-modulus", s.cell.bending_modulus, "bending modulus kappa_B, J (0: no bending)")
      ->capture_default_str();
  cmd->add_option("--volume-ratio", s.cell.volume_modulus_ratio,
                  "kappa_V / kappa_S of ESPResSo's volume force, as in bendlab flow (0: none)")
      ->capture_default_str();
  cmd->add_option("--out", args->out,
                  "output folder (created if missing, its parent must exist); an existing one must be empty")
      ->required();
  cmd->add_flag("--overwrite", args->overwrite,
                "use a non-empty --out, removing an earlier stretch run's files in it (no other file)");
  cmd->add_flag("--plots,!--no-plots", args->plots,
                "run scripts/plot_stretch.py on the output to draw stretch.png (default: on; a plot not made is a "
                "warning)");
  cmd->add_option("--plot-script", args->plot_script,
                  "path of plot_stretch.py (default: share/bendlab/scripts/ of an installed bendlab, or scripts/ "
                  "found in or above the executable's folder or the current folder)");
  cmd->add_option("--python", args->python, "Python interpreter with numpy and matplotlib")->capture_default_str();
  cmd->callback([args] { stretch(*args); });
});

}  // namespace
}  // namespace bendlab::cli
