// bendlab shear: an initially spherical capsule (neo-Hookean membrane + bending) in linear shear
// flow, boundary integral method (paper section 4).
//
// Output folder:
//   timeseries.csv   gamma_t,D,theta,volume,area,E_bend,E_elastic,dt   (one row per accepted step,
//                    flushed as the run goes)
//   snapshot_NNNNN.vtp + shapes.pvd   shapes every --snapshot-every (ParaView collection)
//   checkpoint.json  the state at the last snapshot, for --resume
//   summary.json     D_steady, theta_steady, mean_gamma_dt, steps, wall_seconds, ...
//   D_theta.png      D and theta against gamma t (scripts/plot_shear.py)
#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/core/atomic_file.hpp"
#include "bendlab/flow/shear_simulation.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/mesh/mesh_io.hpp"
#include "cli_common.hpp"
#include "method_cli.hpp"
#include "command.hpp"

namespace fs = std::filesystem;

namespace bendlab::cli {
namespace {

struct ShearArgs {
  std::string solver = "bim", method = "none", mesh = "mt1:1280", out;
  double G = 0.1, kappa_b = 0, t_end = 10, snapshot_every = 0.5, rtol = 1e-7, atol = 1e-6;
  int rings = 0;
  bool resume = false, plot = true;
};

/// "mt1:N", "mt2:N" (N triangles of the homogeneous family), "inh:mt1", "inh:mt2" (320 triangles
/// and three Rivara passes, as in the paper), or a mesh file.
TriMesh capsule_mesh(const std::string& spec) {
  std::smatch m;
  if (std::regex_match(spec, m, std::regex(R"((mt1|mt2|octa):(\d+))"))) {
    const MeshFamily family = parse_mesh_family(m[1]);
    const long triangles = std::stol(m[2]);
    const int level = level_with_triangles(family, triangles);
    if (level < 0 || level > 7)
      throw Error(fmt::format("--mesh {}: {} has no level with {} triangles (up to 7 steps of 4x refinement)", spec,
                              m[1].str(), triangles));
    return sphere_mesh(family, level);
  }
  if (std::regex_match(spec, m, std::regex(R"(inh:(mt1|mt2))"))) return sphere_mesh(parse_mesh_family(m[1]), 2, 3);
  if (!fs::exists(spec))
    throw Error(fmt::format("--mesh '{}' is neither mt1:N, mt2:N, inh:mt1, inh:mt2 nor an existing file", spec));
  return read_mesh(spec);
}

/// D_steady, theta_steady and mean_gamma_dt over gamma t in [5, 10], or over the last half of
/// the run when it ends before gamma t = 10 (table 4 and figure 12b of the paper).
struct Window {
  double begin, end;
};
Window steady_window(double t_end) { return t_end >= 10 ? Window{5, 10} : Window{t_end / 2, t_end}; }

struct Row {
  double t, D, theta, volume, area, E_bend, E_elastic, dt;
};

std::vector<Row> read_timeseries(const fs::path& path) {
  std::vector<Row> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    Row r{};
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream s(line);
    std::string eb;
    if (s >> r.t >> r.D >> r.theta >> r.volume >> r.area >> eb >> r.E_elastic >> r.dt) {
      r.E_bend = eb == "nan" ? std::numeric_limits<double>::quiet_NaN() : std::stod(eb);
      rows.push_back(r);
    }
  }
  return rows;
}

const char* kHeader = "gamma_t,D,theta,volume,area,E_bend,E_elastic,dt";

std::string format_row(const Row& r) {
  return fmt::format("{:.10g},{:.12g},{:.12g},{:.15g},{:.15g},{},{:.12g},{:.6g}\n", r.t, r.D, r.theta, r.volume,
                     r.area, std::isnan(r.E_bend) ? std::string("nan") : fmt::format("{:.12g}", r.E_bend),
                     r.E_elastic, r.dt);
}

nlohmann::json points_to_json(const Points& x) {
  std::vector<double> flat(x.data(), x.data() + x.size());
  return flat;
}

Points points_from_json(const nlohmann::json& j, Eigen::Index n) {
  const auto flat = j.get<std::vector<double>>();
  if (static_cast<Eigen::Index>(flat.size()) != 3 * n)
    throw Error(fmt::format("checkpoint has {} coordinates, the mesh needs {}", flat.size(), 3 * n));
  Points x(n, 3);
  std::copy(flat.begin(), flat.end(), x.data());
  return x;
}

/// The arguments a resumed run must share with the run it continues.
nlohmann::json run_identity(const ShearArgs& a) {
  return {{"method", a.method}, {"rings", a.rings}, {"mesh", a.mesh}, {"G", a.G}, {"kappa_b", a.kappa_b}};
}

void run_shear(const ShearArgs& a) {
  // Everything is checked before any work starts.
  require_positive("--G", a.G);
  require_positive("--kappa-b", a.kappa_b, true);
  require_positive("--t-end", a.t_end);
  require_positive("--snapshot-every", a.snapshot_every);
  require_positive("--rtol", a.rtol);
  require_positive("--atol", a.atol);
  if (a.method == "none" && a.kappa_b > 0)
    throw Error("--kappa-b > 0 needs a bending --method (" + method_names_joined() + ")");
  std::unique_ptr<BendingMethod> bending;
  if (a.method != "none") {
    MethodOptions options;
    if (a.rings != 0) options["rings"] = std::to_string(a.rings);
    bending = make_bending_method(a.method, options);
  }
  const fs::path out = a.out;
  if (fs::exists(out) && !fs::is_directory(out)) throw Error(fmt::format("--out '{}' is a file, not a folder", a.out));
  const fs::path checkpoint = out / "checkpoint.json";
  if (a.resume && !fs::exists(checkpoint))
    throw Error(fmt::format("--resume: no checkpoint in '{}' to resume from", a.out));
  const TriMesh mesh = capsule_mesh(a.mesh);
  fs::create_directories(out);

  ShearParameters params{a.G, a.kappa_b, a.t_end, a.rtol, a.atol};
  ShearSimulation sim(mesh, params, bending.get());

  std::vector<std::pair<double, std::string>> snapshots;
  std::int64_t steps_before = 0;
  double wall_before = 0;
  if (a.resume) {
    const auto j = nlohmann::json::parse(std::ifstream(checkpoint));
    if (j.at("arguments") != run_identity(a))
      throw Error(fmt::format("--resume: --method, --mesh, --G or --kappa-b differ from the run in '{}' ({})", a.out,
                              j.at("arguments").dump()));
    sim.restart(points_from_json(j.at("positions"), mesh.num_vertices()), j.at("time"), j.at("dt_next"));
    snapshots = j.at("snapshots").get<decltype(snapshots)>();
    steps_before = j.at("steps");
    wall_before = j.at("wall_seconds");
    note(fmt::format("resuming at gamma t = {:.4g} from {}", sim.time(), checkpoint.string()));
  }

  // The time series: on resume keep the rows up to the checkpoint, then append.
  const fs::path series_path = out / "timeseries.csv";
  std::vector<Row> rows;
  if (a.resume) {
    for (const Row& r : read_timeseries(series_path))
      if (r.t <= sim.time() * (1 + 1e-12)) rows.push_back(r);
  }
  std::ofstream series(series_path, std::ios::trunc);
  if (!series) throw Error(fmt::format("cannot write '{}'", series_path.string()));
  series << kHeader << '\n';
  for (const Row& r : rows) series << format_row(r);
  series.flush();

  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  double last_progress = -1e9;
  const double t_start = sim.time();
  double next_snapshot = snapshots.empty() ? 0.0 : snapshots.back().first + a.snapshot_every;

  auto write_snapshot = [&](const Points& x, double t, double dt_next, std::int64_t steps) {
    const std::string name = fmt::format("snapshot_{:05d}.vtp", static_cast<int>(snapshots.size()));
    write_mesh(out / name, sim.topology(), x);
    snapshots.emplace_back(t, name);
    write_pvd(out / "shapes.pvd", snapshots);
    nlohmann::json j = {
        {"arguments", run_identity(a)},
        {"time", t}, {"dt_next", dt_next}, {"steps", steps}, {"wall_seconds", wall_before + elapsed()},
        {"snapshots", snapshots}, {"positions", points_to_json(x)}};
    AtomicFile f(checkpoint);
    f.stream() << j.dump();
    f.commit();
  };
  if (!a.resume) write_snapshot(sim.positions(), sim.time(), 0, 0);
  next_snapshot = snapshots.back().first + a.snapshot_every;

  std::int64_t steps = steps_before;
  const CashKarpStats stats = sim.run([&](const ShearSample& s) {
    ++steps;
    const Row r{s.time, s.D, s.theta, s.volume, s.area, s.E_bend ? *s.E_bend : std::numeric_limits<double>::quiet_NaN(),
                s.E_elastic, s.dt};
    rows.push_back(r);
    series << format_row(r);
    series.flush();
    if (s.time >= next_snapshot - 1e-9 * a.snapshot_every || s.time >= a.t_end - 1e-12) {
      write_snapshot(*s.positions, s.time, s.dt_next, steps);
      next_snapshot += a.snapshot_every;
    }
    const double now = elapsed();
    if (now - last_progress >= 2.0 || s.time >= a.t_end - 1e-12) {
      last_progress = now;
      const double done = (s.time - t_start) / (a.t_end - t_start);
      const double eta = done > 0 ? now * (1 - done) / done : 0;
      note(fmt::format("gamma t = {:7.4f} / {:g} ({:3.0f}%)  steps {:6d}  gamma dt {:.2e}  D {:.5f}  theta {:.4f}  "
                       "elapsed {:.0f} s  ETA {:.0f} s",
                       s.time, a.t_end, 100 * done, steps, s.dt, s.D, s.theta, now, eta));
    }
    return true;
  });
  series.close();

  // Summary over the steady window.
  const Window w = steady_window(a.t_end);
  double weight = 0, D = 0, theta = 0, dt_sum = 0;
  int dt_count = 0;
  for (size_t k = 0; k < rows.size(); ++k) {
    if (rows[k].t < w.begin || rows[k].t > w.end + 1e-12) continue;
    // Each row's values hold over the step that led to it: dt-weighted time average.
    D += rows[k].D * rows[k].dt;
    theta += rows[k].theta * rows[k].dt;
    weight += rows[k].dt;
    dt_sum += rows[k].dt;
    ++dt_count;
  }
  nlohmann::json summary = {
      {"solver", a.solver}, {"method", a.method}, {"mesh", a.mesh},
      {"vertices", mesh.num_vertices()}, {"triangles", mesh.num_faces()},
      {"G", a.G}, {"kappa_b_hat", a.kappa_b}, {"t_end", a.t_end}, {"rtol", a.rtol}, {"atol", a.atol},
      {"steady_window", {w.begin, w.end}},
      {"D_steady", weight > 0 ? D / weight : std::numeric_limits<double>::quiet_NaN()},
      {"theta_steady", weight > 0 ? theta / weight : std::numeric_limits<double>::quiet_NaN()},
      {"mean_gamma_dt", dt_count > 0 ? dt_sum / dt_count : std::numeric_limits<double>::quiet_NaN()},
      {"steps", steps}, {"rejected_steps", stats.rejected}, {"velocity_evaluations", stats.rhs_evaluations},
      {"final_volume", rows.empty() ? sim.initial_volume() : rows.back().volume},
      {"initial_volume", sim.initial_volume()},
      {"wall_seconds", wall_before + elapsed()}};
  if (weight > 0 && !std::isfinite(summary["D_steady"].get<double>())) summary["D_steady"] = nullptr;
  AtomicFile f(out / "summary.json");
  f.stream() << summary.dump(2) << '\n';
  f.commit();
  std::cout << summary.dump() << std::endl;

  if (a.plot) {
    const std::string cmd = fmt::format("/usr/bin/python3 '{}/scripts/plot_shear.py' '{}'", BENDLAB_SOURCE_DIR, out.string());
    if (std::system(cmd.c_str()) != 0) note("warning: the plot was not made (needs /usr/bin/python3 with matplotlib)");
  }
}

const CommandRegistration registration([](CLI::App& app) {
  auto args = std::make_shared<ShearArgs>();
  auto* cmd = app.add_subcommand("shear", "Simulate an initially spherical capsule (neo-Hookean membrane plus "
                                          "bending) in linear shear flow u = gamma z e_x at zero Reynolds number");
  cmd->add_option("--solver", args->solver, "flow solver: bim (boundary integral method)")
      ->check(CLI::IsMember({"bim"}))->capture_default_str();
  cmd->add_option("--method", args->method, "bending method: none, " + method_names_joined())
      ->check(CLI::IsMember(method_choices_with_none()))->capture_default_str();
  cmd->add_option("--rings", args->rings, "fitting support of E and ED (1, 2, 3)")->check(CLI::Range(1, 3));
  cmd->add_option("--mesh", args->mesh, "mt1:N or mt2:N (N triangles: 320, 1280, 5120, ...), inh:mt1 or inh:mt2 "
                                        "(320 triangles + 3 Rivara passes), or a mesh file (.off, .obj, .ply)")
      ->capture_default_str();
  cmd->add_option("--G", args->G, "dimensionless shear rate mu gamma R / kS")->capture_default_str();
  cmd->add_option("--kappa-b", args->kappa_b, "dimensionless bending modulus kB / (R^2 kS)")->capture_default_str();
  cmd->add_option("--t-end", args->t_end, "end of the run in gamma t")->capture_default_str();
  cmd->add_option("--rtol", args->rtol, "relative tolerance of the Cash-Karp stepper")->capture_default_str();
  cmd->add_option("--atol", args->atol, "absolute tolerance of the Cash-Karp stepper, in units of R")->capture_default_str();
  cmd->add_option("--snapshot-every", args->snapshot_every, "gamma t between .vtp snapshots and checkpoints")
      ->capture_default_str();
  cmd->add_flag("--resume", args->resume, "continue the run in --out from its last checkpoint");
  cmd->add_flag("!--no-plot", args->plot, "do not draw D_theta.png");
  cmd->add_option("--out", args->out, "output folder (created if missing)")->required();
  cmd->callback([args] { run_shear(*args); });
});

}  // namespace
}  // namespace bendlab::cli
