// bendlab rbc: the static red-blood-cell benchmark of the paper's section 3 (tables 2 and 3,
// figures 3-10, B.19-B.23): errors of every method against the exact RBC, their convergence,
// per-node values for the plots, VTK files of the per-node errors, and the plots.
#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "bendlab/analysis/convergence.hpp"
#include "bendlab/analysis/rbc_study.hpp"
#include "bendlab/core/atomic_file.hpp"
#include "bendlab/mesh/mesh_io.hpp"
#include "cli_common.hpp"
#include "method_cli.hpp"
#include "command.hpp"

namespace bendlab::cli {
namespace {

namespace fs = std::filesystem;

struct RbcArgs {
  std::vector<std::string> families = {"mt1", "mt2", "octa", "inhomogeneous"};
  std::vector<std::string> methods = bending_method_names();
  int max_triangles = 81920;  // the paper's largest meshes; the whole study takes well under a minute
  int rings = 0;  // 0: the methods' default
  std::string out;
  bool plots = true;
  std::string plot_script;
  std::string python = "/usr/bin/python3";
};

// The meshes whose per-node errors go to .vtp files (figures 9 and B.22).
constexpr int kVtkTriangles = 5120;
const std::vector<std::string> kVtkFamilies = {"mt1", "mt2"};

std::string num(double v) { return std::isfinite(v) ? fmt::format("{:.17g}", v) : "nan"; }

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

// scripts/plot_rbc.py: --plot-script, else the source tree the executable was built from, else
// searched upwards from the executable's folder and from the current folder (an installed or
// moved build).
fs::path find_plot_script(const RbcArgs& a) {
  if (!a.plot_script.empty()) return a.plot_script;
#ifdef BENDLAB_SOURCE_DIR
  if (const fs::path p = fs::path(BENDLAB_SOURCE_DIR) / "scripts" / "plot_rbc.py"; fs::is_regular_file(p)) return p;
#endif
  std::vector<fs::path> starts;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) starts.push_back(exe.parent_path());
  starts.push_back(fs::current_path());
  for (fs::path dir : starts)
    for (int up = 0; up < 5 && !dir.empty(); ++up, dir = dir.parent_path()) {
      const fs::path candidate = dir / "scripts" / "plot_rbc.py";
      if (fs::is_regular_file(candidate)) return candidate;
      if (dir == dir.parent_path()) break;
    }
  return {};
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

void write_text(const fs::path& path, const std::string& text) {
  AtomicFile f(path);
  f.stream() << text;
  f.commit();
}

void write_errors_csv(const fs::path& path, const std::vector<ErrorRow>& rows) {
  AtomicFile f(path);
  f.stream() << "family,triangles,h,method,quantity,max_error,avg_error\n";
  for (const ErrorRow& r : rows)
    f.stream() << fmt::format("{},{},{},{},{},{},{}\n", r.family, r.triangles, num(r.h), r.method, r.quantity,
                              num(r.max_error), num(r.avg_error));
  f.commit();
}

void write_timings_csv(const fs::path& path, const RbcStudyResult& s) {
  AtomicFile f(path);
  f.stream() << "family,triangles,vertices,h,method,seconds\n";
  for (const MeshRun& m : s.meshes)
    for (const MethodRun& r : m.methods)
      f.stream() << fmt::format("{},{},{},{},{},{}\n", m.family, m.triangles, m.vertices, num(m.h), r.method,
                                num(r.seconds));
  f.commit();
}

// Long format, one line per method and node: what the value-vs-angle plots read.
void write_values_csv(const fs::path& path, const MeshRun& m) {
  AtomicFile f(path);
  f.stream() << "method,node,theta,H,H_exact,K,K_exact,lapH,lapH_exact,f_abs,f_abs_exact,eps_n,eps_H,eps_K,"
                "eps_lapH,eps_f\n";
  for (const MethodRun& r : m.methods) {
    const BendingResult& v = r.result;
    const NodeErrors& e = r.node_errors;
    auto at = [](const Scalars& s, int i) { return s.size() > i ? s[i] : NAN; };
    for (int i = 0; i < m.vertices; ++i) {
      const double f_abs = v.force_density.rows() > i ? v.force_density.row(i).norm() : NAN;
      f.stream() << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", r.method, i, num(m.theta[i]),
                                num(at(v.H, i)), num(m.analytic.H[i]), num(at(v.K, i)), num(m.analytic.K[i]),
                                num(at(v.lapH, i)), num(m.analytic.lapH[i]), num(f_abs),
                                num(m.analytic.f.row(i).norm()), num(e.n[i]), num(e.H[i]), num(e.K[i]),
                                num(e.lapH[i]), num(e.f[i]));
    }
  }
  f.commit();
}

void write_vtk(const fs::path& dir, const MeshRun& m) {
  for (const MethodRun& r : m.methods) {
    auto defined = [&](const Scalars& s) { return s.size() == m.vertices ? s : Scalars::Constant(m.vertices, NAN); };
    auto defined3 = [&](const Points& p) { return p.rows() == m.vertices ? p : Points::Constant(m.vertices, 3, NAN); };
    VertexFields fields;
    fields.scalars = {{"eps_n", r.node_errors.n},        {"eps_H", r.node_errors.H},
                      {"eps_K", r.node_errors.K},        {"eps_lapH", r.node_errors.lapH},
                      {"eps_f", r.node_errors.f},        {"theta", m.theta},
                      {"H", defined(r.result.H)},        {"H_exact", m.analytic.H},
                      {"K", defined(r.result.K)},        {"K_exact", m.analytic.K},
                      {"lapH", defined(r.result.lapH)},  {"lapH_exact", m.analytic.lapH}};
    fields.vectors = {{"normal", defined3(r.result.normal)},
                      {"normal_exact", m.analytic.normal},
                      {"f", defined3(r.result.force_density)},
                      {"f_exact", m.analytic.f}};
    write_mesh(dir / fmt::format("errors_{}_{}_{}.vtp", m.family, m.triangles, r.method), *m.topology, m.x, fields);
  }
}

nlohmann::json to_json(const RbcStudyResult& s, const std::vector<ErrorRow>& rows, const std::vector<RateFit>& fits,
                       const std::vector<InhomogeneityCheck>& checks, const ConvergenceThresholds& ct,
                       const InhomogeneityThresholds& it, int rings) {
  using nlohmann::json;
  auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  json j;
  j["surface"] = "rbc";
  j["radius"] = s.options.radius;
  j["kappa_b"] = s.options.kappa_b;
  j["maxima"] = {{"H", s.maxima.H}, {"K", s.maxima.K}, {"lapH", s.maxima.lapH}, {"f", s.maxima.f}};
  j["options"] = {{"families", s.options.families},
                  {"methods", s.options.methods},
                  {"max_triangles", s.options.max_triangles},
                  {"rings", rings}};
  j["thresholds"] = {{"tail_points", ct.tail_points},
                     {"to_zero_slope", ct.to_zero_slope},
                     {"diverge_slope", ct.diverge_slope},
                     {"exact_error", ct.exact_error},
                     {"inhomogeneous_factor", it.factor}};
  j["meshes"] = json::array();
  for (const MeshRun& m : s.meshes)
    j["meshes"].push_back({{"family", m.family},
                           {"origin", m.origin},
                           {"inhomogeneous", m.inhomogeneous},
                           {"level", m.level},
                           {"triangles", m.triangles},
                           {"vertices", m.vertices},
                           {"h", m.h}});
  j["rows"] = json::array();
  for (const ErrorRow& r : rows)
    j["rows"].push_back({{"family", r.family},
                         {"triangles", r.triangles},
                         {"h", r.h},
                         {"method", r.method},
                         {"quantity", r.quantity},
                         {"max_error", number(r.max_error)},
                         {"avg_error", number(r.avg_error)}});
  j["timings"] = json::array();
  for (const MeshRun& m : s.meshes)
    for (const MethodRun& r : m.methods)
      j["timings"].push_back({{"family", m.family},
                              {"triangles", m.triangles},
                              {"vertices", m.vertices},
                              {"method", r.method},
                              {"seconds", r.seconds}});
  j["rates"] = json::array();
  for (const RateFit& f : fits) {
    std::vector<json> err;
    for (double e : f.error) err.push_back(number(e));
    j["rates"].push_back({{"family", f.family},
                          {"method", f.method},
                          {"quantity", f.quantity},
                          {"measure", f.measure},
                          {"triangles", f.triangles},
                          {"h", f.h},
                          {"error", err},
                          {"slope_all", number(f.fit.slope_all)},
                          {"slope_tail", number(f.fit.slope_tail)},
                          {"slope_last", number(f.fit.slope_last)},
                          {"trend", to_string(f.fit.trend)},
                          {"symbol", symbol(f.fit.trend)}});
  }
  j["inhomogeneous"] = json::array();
  for (const InhomogeneityCheck& c : checks)
    j["inhomogeneous"].push_back({{"family", c.family},
                                  {"origin", c.origin},
                                  {"method", c.method},
                                  {"quantity", c.quantity},
                                  {"triangles", c.triangles},
                                  {"h", c.h},
                                  {"max_error", number(c.max_error)},
                                  {"avg_error", number(c.avg_error)},
                                  {"ref_max", number(c.ref_max)},
                                  {"ref_avg", number(c.ref_avg)},
                                  {"ratio_max", number(c.ratio_max)},
                                  {"ratio_avg", number(c.ratio_avg)},
                                  {"symbol", symbol(c.trouble)}});
  return j;
}

std::string table2_text(const std::vector<RateFit>& fits, const RbcStudyResult& s, const ConvergenceThresholds& ct) {
  std::string md = fmt::format(
      "# Table 2: convergence on the RBC\n\n"
      "Cells: symbol (least-squares slope of log(error) against log(1/h) over the {} finest meshes).\n"
      "● converges to zero: that slope and the slope between the two finest meshes are both <= {};\n"
      "■ diverges: either slope >= {:+};\n"
      "○ converges to a systematic error: otherwise. Empty: the method does not compute the quantity.\n",
      ct.tail_points, ct.to_zero_slope, ct.diverge_slope);
  for (const std::string fam : {"mt1", "mt2", "octa"}) {
    if (std::none_of(fits.begin(), fits.end(), [&](const RateFit& f) { return f.family == fam; })) continue;
    for (const std::string measure : {"max", "avg"})
      md += fmt::format("\n## {}, {} error\n\n{}", fam, measure == "max" ? "maximal" : "average",
                        table2_markdown(fits, fam, measure, s.options.methods));
  }
  return md;
}

std::string table3_text(const std::vector<InhomogeneityCheck>& checks, const RbcStudyResult& s,
                        const InhomogeneityThresholds& it) {
  std::string md = fmt::format(
      "# Table 3: the inhomogeneous meshes\n\n"
      "Cells: symbol (r_max / r_avg), r = error of the inhomogeneous mesh / error of its homogeneous\n"
      "family at the same h (log-log interpolation between the homogeneous meshes around it).\n"
      "● no troubles: r_max < {0} and r_avg < {0}; ○ only the maximal error worse: r_max >= {0}, r_avg < {0};\n"
      "■ the average error worse too: r_avg >= {0}.\n",
      it.factor);
  for (const MeshRun& m : s.meshes) {
    if (!m.inhomogeneous) continue;
    std::vector<InhomogeneityCheck> mine;
    for (const auto& c : checks)
      if (c.family == m.family) mine.push_back(c);
    md += fmt::format("\n## {} ({} triangles, h = {:.4f}) against {}\n\n{}", m.family, m.triangles, m.h, m.origin,
                      table3_markdown(mine, s.options.methods));
  }
  return md;
}

void run_rbc(const RbcArgs& a) {
  RbcStudyOptions o;
  o.families = a.families;
  o.methods = a.methods;
  o.max_triangles = a.max_triangles;
  if (a.rings != 0) {
    if (a.rings < 1 || a.rings > 3) throw Error(fmt::format("--rings must be 1, 2 or 3, got {}", a.rings));
    o.method_options["rings"] = std::to_string(a.rings);
  }
  validate(o);
  if (a.out.empty()) throw Error("--out: no output folder given");
  const fs::path out = a.out;
  require_writable_dir(out);
  fs::path script;
  if (a.plots) {
    script = find_plot_script(a);
    if (script.empty() || !fs::is_regular_file(script))
      throw Error("--plot-script: scripts/plot_rbc.py not found near the executable or the current folder "
                  "(give --plot-script PATH, or --no-plots)");
  }

  o.progress = [](const std::string& line) { note(line); };
  const RbcStudyResult s = run_rbc_study(o);
  const std::vector<ErrorRow> rows = s.rows();

  const ConvergenceThresholds ct;
  const InhomogeneityThresholds it;
  const std::vector<RateFit> fits = fit_rates(rows, {"mt1", "mt2", "octa"}, ct);
  std::vector<InhomogeneityCheck> checks;
  for (const MeshRun& m : s.meshes)
    if (m.inhomogeneous)
      for (auto& c : compare_inhomogeneous(rows, m.family, m.origin, it)) checks.push_back(std::move(c));

  write_errors_csv(out / "errors.csv", rows);
  write_timings_csv(out / "timings.csv", s);
  write_text(out / "errors.json", to_json(s, rows, fits, checks, ct, it, a.rings).dump(1) + "\n");
  write_text(out / "table2.md", table2_text(fits, s, ct));
  write_text(out / "table3.md", table3_text(checks, s, it));
  for (const MeshRun& m : s.meshes) {
    if (!m.has_nodes) continue;
    write_values_csv(out / fmt::format("values_{}_{}.csv", m.family, m.triangles), m);
    if (m.triangles == kVtkTriangles &&
        std::find(kVtkFamilies.begin(), kVtkFamilies.end(), m.family) != kVtkFamilies.end())
      write_vtk(out, m);
  }
  note(fmt::format("rbc: wrote errors.csv, errors.json, timings.csv, table2.md, table3.md and values_*.csv to {}",
                   out.string()));

  if (a.plots) {
    const std::string cmd = fmt::format("{} {} {}", shell_quote(a.python), shell_quote(script.string()),
                                        shell_quote(out.string()));
    note("rbc: " + cmd);
    const int status = std::system(cmd.c_str());
    if (status != 0)
      throw Error(fmt::format("the plot script failed (status {}); the data files in {} are complete", status,
                              out.string()));
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

const CommandRegistration registration([](CLI::App& app) {
  auto args = std::make_shared<RbcArgs>();
  auto families = std::make_shared<std::string>("mt1,mt2,octa,inhomogeneous");
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
                  "inhomogeneous (320-triangle MT1 and MT2 spheres + 3 Rivara passes; always run in full)")
      ->capture_default_str();
  cmd->add_option("--max-triangles", args->max_triangles,
                  "largest homogeneous mesh, at least 320 (320, 1280, 5120, 20480, 81920 for MT1/MT2)")
      ->capture_default_str();
  cmd->add_option("--methods", *methods, "comma-separated bending methods among " + method_names_joined())
      ->capture_default_str();
  cmd->add_option("--rings", args->rings, "neighbour rings of the fits of Methods E and ED (1, 2 or 3; "
                                          "default: the methods' own default)");
  cmd->add_option("--out", args->out, "output folder (created if missing)")->required();
  cmd->add_flag("--plots,!--no-plots", args->plots, "run scripts/plot_rbc.py on the output to draw the PNG plots "
                                                   "(default: on)");
  cmd->add_option("--plot-script", args->plot_script,
                  "path of plot_rbc.py (default: scripts/plot_rbc.py of the source tree, or found above the "
                  "executable or the current folder)");
  cmd->add_option("--python", args->python, "Python interpreter with numpy and matplotlib")->capture_default_str();
  cmd->callback([args, families, methods] {
    args->families = split_list(*families);
    args->methods = split_list(*methods);
    run_rbc(*args);
  });
});

}  // namespace
}  // namespace bendlab::cli
