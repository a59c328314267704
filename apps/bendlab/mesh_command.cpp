// bendlab mesh: a mesh of the paper's families on a sphere, RBC or spheroid.
#include <fmt/format.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "bendlab/geometry/measures.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/mesh/mesh_io.hpp"
#include "cli_common.hpp"
#include "command.hpp"

namespace bendlab::cli {
namespace {

struct MeshArgs {
  std::string family = "mt1";
  int level = 2;
  int rivara = 0;
  std::string shape = "sphere";
  double radius = 1.0;
  std::vector<double> axes;
  double jitter = kDefaultJitterFraction;
  std::uint64_t jitter_seed = kDefaultJitterSeed;
  bool jitter_given = false;  // --jitter or --jitter-seed on the command line
  std::string out;
};

void run_mesh(const MeshArgs& a) {
  check_sphere_mesh_arguments(a.level, a.rivara, "--level", "--rivara");
  require_extension("--out", a.out, {".off", ".ply", ".obj", ".vtp"});
  require_writable_parent("--out", a.out);
  const auto surface = surface_from_options(a.shape, a.radius, a.axes);
  const MeshFamily family = parse_mesh_family(a.family);
  if (a.jitter_given && family != MeshFamily::Irregular)
    throw Error(fmt::format("--jitter and --jitter-seed apply to --family irregular only, not {}", a.family));

  TriMesh sphere = sphere_mesh(family == MeshFamily::Irregular ? MeshFamily::MT1 : family, a.level, 0);
  if (family == MeshFamily::Irregular) {
    try {
      sphere = irregular_sphere_mesh(a.level, a.jitter, a.jitter_seed);
    } catch (const Error& e) {
      throw Error(fmt::format("--jitter: {}", e.what()));
    }
  }
  for (int p = 0; p < a.rivara; ++p) sphere = rivara_pass(sphere);
  const TriMesh mesh = sphere.with_positions(surface->map_from_unit_sphere(sphere.positions()));
  write_mesh(a.out, mesh.topology(), mesh.positions());

  const auto v = valence_stats(mesh.topology());
  nlohmann::json summary = {
      {"vertices", mesh.num_vertices()},
      {"triangles", mesh.num_faces()},
      {"mean_edge_length", mean_edge_length(mesh.topology(), mesh.positions())},
      {"min_valence", v.min},
      {"max_valence", v.max},
      {"min_angle_deg", min_corner_angle(mesh.topology(), mesh.positions()) * 180.0 / M_PI},
  };
  if (family == MeshFamily::Irregular) {
    summary["jitter"] = a.jitter;
    summary["jitter_seed"] = a.jitter_seed + static_cast<std::uint64_t>(a.level);
  }
  std::cout << summary.dump() << std::endl;
}

const CommandRegistration mesh_registration([](CLI::App& app) {
  auto args = std::make_shared<MeshArgs>();
  auto* cmd = app.add_subcommand("mesh", "Generate a mesh of the paper's families (MT1, MT2, octahedron, "
                                         "Rivara passes) or the irregular family and map it to a sphere, RBC "
                                         "or spheroid; prints a one-line JSON summary");
  cmd->add_option("--family", args->family, "mt1 (Loop refinement of the icosahedron), mt2 (midpoint), "
                                             "octa (midpoint refinement of the octahedron), irregular (MT1 "
                                             "with every node jittered, see --jitter)")
      ->check(CLI::IsMember({"mt1", "mt2", "octa", "irregular"}, CLI::ignore_case))->capture_default_str();
  cmd->add_option("--level", args->level, "refinement steps of the base, 0..8 (mt1 level 2 = 320 triangles)")->capture_default_str();
  cmd->add_option("--rivara", args->rivara, "passes of Rivara's longest-edge bisection after refinement, 0..6")->capture_default_str();
  cmd->add_option("--shape", args->shape, "sphere, rbc (eq. 15), oblate or prolate spheroid")
      ->check(CLI::IsMember({"sphere", "rbc", "oblate", "prolate"}))->capture_default_str();
  cmd->add_option("--radius", args->radius, "sphere radius, or the RBC's large half-axis R")->capture_default_str();
  cmd->add_option("--axes", args->axes, "spheroid half-axes a,c (equatorial, polar)")->delimiter(',')->expected(2);
  cmd->add_option("--jitter", args->jitter,
                  "irregular family: every node of the MT1 sphere is moved in its tangent plane by this fraction "
                  "of the mean length of its edges, in a direction uniform in [0, 2 pi) from std::mt19937_64, "
                  "then projected back onto the sphere (before the map to --shape); a fraction that folds a "
                  "triangle is refused (with the default seeds the first fold on levels 0-6, 20-81920 triangles, comes "
                  "at fractions from 0.39 (20480 triangles) to 0.54 (20))")
      ->capture_default_str();
  cmd->add_option("--jitter-seed", args->jitter_seed,
                  "irregular family: base seed; level k is jittered with seed (base + k)")
      ->capture_default_str();
  cmd->add_option("--out", args->out, "output mesh: .off, .ply, .obj or .vtp")->required();
  cmd->callback([args, cmd] {
    args->jitter_given = cmd->count("--jitter") + cmd->count("--jitter-seed") > 0;
    run_mesh(*args);
  });
});

}  // namespace
}  // namespace bendlab::cli
