#include "bendlab/analysis/rbc_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "bendlab/core/atomic_file.hpp"
#include "bendlab/mesh/mesh_io.hpp"

namespace bendlab {
namespace {

namespace fs = std::filesystem;

std::string num(double v) { return std::isfinite(v) ? fmt::format("{:.17g}", v) : "nan"; }

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
      if (r.refused.empty())
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
    if (!r.has_nodes) continue;  // refused the mesh
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
    if (!r.has_nodes) continue;  // refused the mesh
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
  if (s.options.c0 != 0 || s.options.ade_alpha != 0) {  // absent for the paper's study (files unchanged)
    j["c0"] = s.options.c0;
    j["ade"] = {{"alpha", s.options.ade_alpha}, {"d", s.options.ade_d}, {"dA0", s.options.ade_da0}};
  }
  j["maxima"] = {{"H", s.maxima.H}, {"K", s.maxima.K}, {"lapH", s.maxima.lapH}, {"f", s.maxima.f}};
  j["options"] = {{"families", s.options.families},
                  {"methods", s.options.methods},
                  {"max_triangles", s.options.max_triangles},
                  {"base", s.options.base},
                  {"rings", rings},
                  {"jitter", s.options.jitter},
                  {"jitter_seed", s.options.jitter_seed}};
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
      if (r.refused.empty())
        j["timings"].push_back({{"family", m.family},
                              {"triangles", m.triangles},
                              {"vertices", m.vertices},
                              {"method", r.method},
                              {"seconds", r.seconds}});
  // Meshes a method refused (needs_admissible_mesh), with its one-line reason.
  j["refused"] = json::array();
  for (const MeshRun& m : s.meshes)
    for (const MethodRun& r : m.methods)
      if (!r.refused.empty())
        j["refused"].push_back({{"family", m.family}, {"triangles", m.triangles}, {"method", r.method},
                                {"reason", r.refused}});
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
  for (const std::string fam : {"mt1", "mt2", "octa", "irregular"}) {
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
    std::vector<std::string> refused;
    for (const MethodRun& r : m.methods)
      if (!r.refused.empty()) refused.push_back(r.method);
    md += fmt::format("\n## {} ({} triangles, h = {:.4f}) against {}\n\n{}", m.family, m.triangles, m.h, m.origin,
                      table3_markdown(mine, s.options.methods, refused));
    for (const MethodRun& r : m.methods)
      if (!r.refused.empty()) md += fmt::format("\nn/a: method {} refuses this mesh: {}\n", r.method, r.refused);
  }
  return md;
}


// The --rings the study ran with (0: the methods' default), as errors.json has always recorded it.
int rings_option(const RbcStudyResult& s) {
  const auto it = s.options.method_options.find("rings");
  return it == s.options.method_options.end() ? 0 : std::stoi(it->second);
}

}  // namespace

std::vector<std::string> write_rbc_report(const fs::path& out, const RbcStudyResult& s,
                                          const RbcReportOptions& options) {
  const std::vector<ErrorRow> rows = s.rows();
  const ConvergenceThresholds& ct = options.convergence;
  const InhomogeneityThresholds& it = options.inhomogeneity;
  const std::vector<RateFit> fits = fit_rates(rows, options.fitted_families, ct);
  std::vector<InhomogeneityCheck> checks;
  for (const MeshRun& m : s.meshes)
    if (m.inhomogeneous)
      for (auto& c : compare_inhomogeneous(rows, m.family, m.origin, it)) checks.push_back(std::move(c));

  std::vector<std::string> written;
  auto wrote = [&](const std::string& name) { written.push_back(name); return out / name; };
  write_errors_csv(wrote("errors.csv"), rows);
  write_timings_csv(wrote("timings.csv"), s);
  write_text(wrote("errors.json"), to_json(s, rows, fits, checks, ct, it, rings_option(s)).dump(1) + "\n");
  write_text(wrote("table2.md"), table2_text(fits, s, ct));
  write_text(wrote("table3.md"), table3_text(checks, s, it));
  for (const MeshRun& m : s.meshes) {
    if (!m.has_nodes) continue;
    write_values_csv(wrote(fmt::format("values_{}_{}.csv", m.family, m.triangles)), m);
    const auto& vf = options.vtk_families;
    if (m.triangles == options.vtk_triangles && std::find(vf.begin(), vf.end(), m.family) != vf.end()) {
      write_vtk(out, m);
      for (const MethodRun& r : m.methods) written.push_back(fmt::format("errors_{}_{}_{}.vtp", m.family, m.triangles, r.method));
    }
  }
  return written;
}

}  // namespace bendlab
