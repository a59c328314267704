#include "bendlab/analysis/rbc_study.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <set>

#include "bendlab/bending/bending_parameters.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/surfaces/surface_of_revolution.hpp"
#include "bendlab/mesh/generators.hpp"

namespace bendlab {

namespace {

constexpr int kMinTriangles = 320;    // MT1/MT2 level 2; the coarsest mesh of the paper
constexpr int kRivaraLevel = 2;       // 320 triangles, as in the paper
constexpr int kRivaraPasses = 3;

MethodOptions options_for(const RbcStudyOptions& o, const std::string& method) {
  return options_for_method(bending_method_info(method), o.method_options);
}

struct MeshSpec {
  std::string family, origin;
  MeshFamily generator;
  int level, passes;
};

int family_triangles(MeshFamily f, int level) {
  return (f == MeshFamily::Octa ? 8 : 20) * (1 << (2 * level));
}

std::vector<MeshSpec> mesh_specs(const RbcStudyOptions& o) {
  std::vector<MeshSpec> specs;
  auto homogeneous = [&](const std::string& name, MeshFamily f, int first_level) {
    for (int level = first_level; family_triangles(f, level) <= o.max_triangles; ++level)
      specs.push_back({name, name, f, level, 0});
  };
  for (const std::string& fam : o.families) {
    if (fam == "mt1") homogeneous("mt1", MeshFamily::MT1, 2);
    if (fam == "mt2") homogeneous("mt2", MeshFamily::MT2, 2);
    if (fam == "octa") homogeneous("octa", MeshFamily::Octa, 3);
    if (fam == "irregular") homogeneous("irregular", MeshFamily::Irregular, 2);
    if (fam == "inhomogeneous") {
      specs.push_back({"rivara-mt1", "mt1", MeshFamily::MT1, kRivaraLevel, kRivaraPasses});
      specs.push_back({"rivara-mt2", "mt2", MeshFamily::MT2, kRivaraLevel, kRivaraPasses});
    }
  }
  return specs;
}

// sphere_mesh(), or with the icosahedron rotated to a vertex at each pole; the irregular family
// jitters MT1 of that orientation with the study's fraction and seed.
TriMesh study_sphere(const MeshSpec& spec, const RbcStudyOptions& o) {
  const bool irregular = spec.generator == MeshFamily::Irregular;
  const MeshFamily generator = irregular ? MeshFamily::MT1 : spec.generator;
  TriMesh m = o.base != "polar" || generator == MeshFamily::Octa ? sphere_mesh(generator, spec.level) : icosahedron_polar();
  if (o.base == "polar" && generator != MeshFamily::Octa)
    for (int k = 0; k < spec.level; ++k) m = generator == MeshFamily::MT1 ? refine_loop(m) : refine_midpoint(m);
  if (irregular) m = jitter_sphere(m, o.jitter, o.jitter_seed + static_cast<std::uint64_t>(spec.level));
  for (int p = 0; p < spec.passes; ++p) m = rivara_pass(m);
  return m;
}

void report(const RbcStudyOptions& o, const std::string& line) {
  if (o.progress) o.progress(line);
}

}  // namespace

const std::vector<std::string>& rbc_study_families() {
  static const std::vector<std::string> f = {"mt1", "mt2", "octa", "inhomogeneous", "irregular"};
  return f;
}

void validate(const RbcStudyOptions& o) {
  if (o.families.empty()) throw Error("--families: no mesh family given");
  for (const std::string& f : o.families)
    if (std::find(rbc_study_families().begin(), rbc_study_families().end(), f) == rbc_study_families().end())
      throw Error(fmt::format("--families: unknown family '{}' (expected mt1, mt2, octa, inhomogeneous, irregular)", f));
  if (o.methods.empty()) throw Error("--methods: no method given");
  for (const auto& [key, value] : o.method_options) {
    bool taken = false;
    for (const MethodInfo& m : bending_methods())
      for (const OptionSpec& s : m.options) taken = taken || s.name == key;
    if (!taken) throw Error(fmt::format("method option '{}': no bending method takes it", key));
  }
  std::set<std::string> seen;
  for (const std::string& m : o.methods) {
    if (!seen.insert(m).second) throw Error(fmt::format("--methods: method '{}' given twice", m));
    try {
      make_bending_method(m, options_for(o, m));  // throws for an unknown name or a refused option
    } catch (const Error& e) {
      throw Error(fmt::format("--methods: {}", e.what()));
    }
  }
  if (o.base != "default" && o.base != "polar")
    throw Error(fmt::format("--base: expected default or polar, got '{}'", o.base));
  if (o.max_triangles < kMinTriangles)
    throw Error(fmt::format("--max-triangles: must be at least {} (the coarsest mesh), got {}", kMinTriangles,
                            o.max_triangles));
  if (!(o.kappa_b > 0) || !std::isfinite(o.kappa_b))
    throw Error(fmt::format("kappa_b must be positive and finite, got {}", o.kappa_b));
  if (!(o.radius > 0) || !std::isfinite(o.radius))
    throw Error(fmt::format("radius must be positive and finite, got {}", o.radius));
  {
    // c0 / ADE: valid parameters, and every method able to take them (A is refused: §5).
    BendingParameters p(o.kappa_b);
    p.c0 = o.c0, p.ade_alpha = o.ade_alpha, p.ade_d = o.ade_d, p.ade_da0 = o.ade_da0;
    p.ade_area = 1.0;  // the exact area, positive (rbc_bending_parameters)
    p.validate();
    if (!p.plain())
      for (const std::string& m : o.methods) make_bending_method(m, options_for(o, m))->check_parameters(p);
  }
  if (o.c0 != 0 || o.ade_alpha != 0) {
    // The exact force density normalises every error: it must be a number (c0 = 1e308 overflows
    // it), or the study would fail after its work began.
    const BendingParameters p = rbc_bending_parameters(o);
    p.validate();  // now with the exact area
    const auto rbc = make_rbc(o.radius);
    const auto& rev = dynamic_cast<const SurfaceOfRevolution&>(*rbc);
    const double c0_only = rev.max_force_density(p.c0, p.kappa_b, 0.0);
    if (!std::isfinite(c0_only))
      throw Error(fmt::format("--c0 {}: the exact force density of the RBC overflows (max |f| = {})", o.c0, c0_only));
    const double lambda = p.ade_lambda(rev.integrals().mean_curvature);
    const double with_ade = rev.max_force_density(p.c0, p.kappa_b, lambda);
    if (!std::isfinite(with_ade))
      throw Error(fmt::format("--ade-alpha {}, --ade-d {}, --ade-da0 {}: the exact force density of the RBC overflows "
                              "(ADE lambda = {}, max |f| = {})",
                              o.ade_alpha, o.ade_d, o.ade_da0, lambda, with_ade));
  }
  if (!(o.jitter >= 0) || !std::isfinite(o.jitter))
    throw Error(fmt::format("--jitter: the fraction must be finite and >= 0, got {}", o.jitter));
  // A fold is found only by making the mesh; the irregular meshes are cheap beside the study.
  for (const MeshSpec& spec : mesh_specs(o)) {
    if (spec.generator != MeshFamily::Irregular) continue;
    try {
      study_sphere(spec, o);
    } catch (const Error& e) {
      throw Error(fmt::format("--jitter: {}", e.what()));
    }
  }
}

Scalars polar_angle(const Points& x) {
  Scalars theta(x.rows());
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const double r = x.row(i).norm();
    theta[i] = std::acos(std::clamp(x(i, 2) / r, -1.0, 1.0));  // clamp: round-off at the poles
  }
  return theta;
}

std::vector<ErrorRow> RbcStudyResult::rows() const {
  std::vector<ErrorRow> rows;
  for (const MeshRun& m : meshes)
    for (const MethodRun& r : m.methods)
      for (std::size_t q = 0; q < kAllQuantities.size(); ++q) {
        const ErrorSummary& s = r.errors[q];
        if (!s.available) continue;
        rows.push_back({m.family, m.triangles, m.h, r.method, to_string(kAllQuantities[q]), s.max, s.average});
      }
  return rows;
}

BendingParameters rbc_bending_parameters(const RbcStudyOptions& o) {
  BendingParameters p(o.kappa_b);
  p.c0 = o.c0;
  p.ade_alpha = o.ade_alpha;
  p.ade_d = o.ade_d;
  p.ade_da0 = o.ade_da0;
  if (p.has_ade()) {
    const auto rbc = make_rbc(o.radius);
    p.ade_area = dynamic_cast<const SurfaceOfRevolution&>(*rbc).integrals().area;
  }
  return p;
}

RbcStudyResult run_rbc_study(const RbcStudyOptions& o) {
  validate(o);
  RbcStudyResult out;
  out.options = o;
  const auto rbc = make_rbc(o.radius);
  out.maxima = rbc->maxima(o.kappa_b);
  const BendingParameters params = rbc_bending_parameters(o);
  // With c0 / ADE: lambda of the exact shape and max|f| of the general force law.
  double lambda = 0;
  if (!params.plain()) {
    const auto& rev = dynamic_cast<const SurfaceOfRevolution&>(*rbc);
    lambda = params.ade_lambda(rev.integrals().mean_curvature);
    out.maxima.f = rev.max_force_density(params.c0, params.kappa_b, lambda);
  }

  std::vector<std::unique_ptr<BendingMethod>> methods;
  for (const std::string& m : o.methods) methods.push_back(make_bending_method(m, options_for(o, m)));

  for (const MeshSpec& spec : mesh_specs(o)) {
    const TriMesh sphere = study_sphere(spec, o);
    const TriMesh mesh(sphere.topology_ptr(), rbc->map_from_unit_sphere(sphere.positions()));
    MeshRun run;
    run.family = spec.family;
    run.origin = spec.origin;
    run.inhomogeneous = spec.passes > 0;
    run.level = spec.level;
    run.triangles = mesh.num_faces();
    run.vertices = mesh.num_vertices();
    run.h = mean_edge_length(mesh.topology(), mesh.positions());
    run.has_nodes = run.inhomogeneous || run.triangles <= o.keep_nodes_max_triangles;
    SurfaceFields analytic = rbc->evaluate(mesh.positions(), o.kappa_b);
    if (!params.plain()) {
      for (Eigen::Index i = 0; i < analytic.H.size(); ++i) {
        analytic.f_normal[i] = membrane_normal_force(analytic.H[i], analytic.K[i], analytic.lapH[i], params.c0,
                                                     params.kappa_b, lambda);
        analytic.f.row(i) = analytic.f_normal[i] * analytic.normal.row(i);
      }
    }
    report(o, fmt::format("rbc: {} level {}{}: {} triangles, {} nodes, h = {:.5f}", run.family, spec.level,
                          spec.passes ? fmt::format(" + {} Rivara passes", spec.passes) : "", run.triangles,
                          run.vertices, run.h));
    for (const auto& method : methods) {
      MethodRun mr;
      mr.method = method->name();
      const auto t0 = std::chrono::steady_clock::now();
      BendingResult result;
      try {
        result = method->compute(mesh.topology(), mesh.positions(), params);
      } catch (const Error& e) {
        if (!bending_method_info(mr.method).capabilities.needs_admissible_mesh) throw;
        mr.refused = e.what();
        mr.errors.assign(kAllQuantities.size(), ErrorSummary{});
        report(o, fmt::format("rbc: {} {} triangles, method {}: refused ({})", run.family, run.triangles,
                              mr.method, mr.refused));
        run.methods.push_back(std::move(mr));
        continue;
      }
      mr.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      NodeErrors errors = node_errors(analytic, out.maxima, result, o.kappa_b);
      for (Quantity q : kAllQuantities) mr.errors.push_back(summarize(errors[q]));
      const ErrorSummary& ef = mr.errors[static_cast<std::size_t>(Quantity::F)];
      report(o, fmt::format("rbc: {} {} triangles, method {}: {:.3f} s, f error max {:.4g} avg {:.4g}", run.family,
                            run.triangles, mr.method, mr.seconds, ef.max, ef.average));
      if (run.has_nodes) {
        mr.has_nodes = true;
        mr.result = std::move(result);
        mr.node_errors = std::move(errors);
      }
      run.methods.push_back(std::move(mr));
    }
    if (run.has_nodes) {
      run.topology = mesh.topology_ptr();
      run.x = mesh.positions();
      run.theta = polar_angle(run.x);
      run.analytic = analytic;
    }
    out.meshes.push_back(std::move(run));
  }
  return out;
}

namespace {
std::string slope_text(double s) { return std::isfinite(s) ? fmt::format("{:+.1f}", s) : "n/a"; }
const std::vector<std::string> kTableQuantities = {"K", "H", "lapH", "f", "n"};
// "| quantity | A | B | ... |" and its separator line.
std::string table_header(const std::vector<std::string>& methods) {
  std::string md = "| quantity |";
  for (const auto& m : methods) md += " " + m + " |";
  md += "\n|---|";
  for (std::size_t i = 0; i < methods.size(); ++i) md += "---|";
  return md + "\n";
}
}  // namespace

std::string table2_markdown(const std::vector<RateFit>& fits, const std::string& family, const std::string& measure,
                            const std::vector<std::string>& methods) {
  std::string md = table_header(methods);
  for (const std::string& q : kTableQuantities) {
    md += "| " + q + " |";
    for (const std::string& m : methods) {
      auto it = std::find_if(fits.begin(), fits.end(), [&](const RateFit& f) {
        return f.family == family && f.method == m && f.quantity == q && f.measure == measure;
      });
      if (it == fits.end())
        md += "  |";
      else
        md += fmt::format(" {} ({}) |", symbol(it->fit.trend), slope_text(it->fit.slope_tail));
    }
    md += "\n";
  }
  return md;
}

std::string table3_markdown(const std::vector<InhomogeneityCheck>& checks, const std::vector<std::string>& methods,
                            const std::vector<std::string>& refused) {
  std::string md = table_header(methods);
  for (const std::string& q : kTableQuantities) {
    md += "| " + q + " |";
    for (const std::string& m : methods) {
      auto it = std::find_if(checks.begin(), checks.end(),
                             [&](const InhomogeneityCheck& c) { return c.method == m && c.quantity == q; });
      if (std::find(refused.begin(), refused.end(), m) != refused.end())
        md += " n/a |";
      else if (it == checks.end())
        md += "  |";
      else
        md += fmt::format(" {} ({:.2g} / {:.2g}) |", symbol(it->trouble), it->ratio_max, it->ratio_avg);
    }
    md += "\n";
  }
  return md;
}

}  // namespace bendlab
