#include "bendlab/mesh/generators.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "bendlab/mesh/jitter.hpp"
#include "bendlab/mesh/subdivision.hpp"

namespace bendlab {

MeshFamily parse_mesh_family(const std::string& name) {
  std::string s = name;
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (s == "mt1") return MeshFamily::MT1;
  if (s == "mt2") return MeshFamily::MT2;
  if (s == "octa") return MeshFamily::Octa;
  if (s == "irregular") return MeshFamily::Irregular;
  throw Error("unknown mesh family '" + name + "' (expected mt1, mt2, octa or irregular)");
}

std::string to_string(MeshFamily family) {
  switch (family) {
    case MeshFamily::MT1: return "mt1";
    case MeshFamily::MT2: return "mt2";
    case MeshFamily::Octa: return "octa";
    case MeshFamily::Irregular: return "irregular";
  }
  throw Error("invalid MeshFamily value");
}

namespace {

void project_rows(Points& x, Eigen::Index first) {
  for (Eigen::Index i = first; i < x.rows(); ++i) x.row(i).normalize();
}

}  // namespace

TriMesh icosahedron() {
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  Points x(12, 3);
  x << -1, p, 0, 1, p, 0, -1, -p, 0, 1, -p, 0,  //
      0, -1, p, 0, 1, p, 0, -1, -p, 0, 1, -p,   //
      p, 0, -1, p, 0, 1, -p, 0, -1, -p, 0, 1;
  project_rows(x, 0);
  Faces f(20, 3);
  f << 0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11,  //
      1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,    //
      3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9,        //
      4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1;
  return TriMesh(std::move(x), f);
}

TriMesh icosahedron_polar() {
  const TriMesh ico = icosahedron();
  const Mat3 r = Eigen::Quaterniond::FromTwoVectors(row(ico.positions(), 0), Vec3::UnitZ()).toRotationMatrix();
  Points x = ico.positions() * r.transpose();
  project_rows(x, 0);
  x.row(0) << 0, 0, 1;
  x.row(3) << 0, 0, -1;
  return TriMesh(std::move(x), ico.faces());
}

TriMesh octahedron() {
  Points x(6, 3);
  x << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  Faces f(8, 3);
  f << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4,  //
      2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  return TriMesh(std::move(x), f);
}

TriMesh refine_loop(const TriMesh& mesh, bool project_to_unit_sphere) {
  const Topology& t = mesh.topology();
  Points y = loop_positions(t, mesh.positions());
  if (project_to_unit_sphere) project_rows(y, 0);
  return TriMesh(split_in_four(t), std::move(y));
}

TriMesh refine_midpoint(const TriMesh& mesh, bool project_to_unit_sphere) {
  const Topology& t = mesh.topology();
  Points y = midpoint_positions(t, mesh.positions());
  // The old nodes are already on the sphere when the input is; only the new ones move.
  if (project_to_unit_sphere) project_rows(y, t.num_vertices());
  return TriMesh(split_in_four(t), std::move(y));
}

namespace {

// Rivara's longest-edge bisection on a mutable triangulation with neighbour links.
// nbr[t][k] is the triangle across the edge opposite corner k of triangle t.
class Bisector {
 public:
  Bisector(const TriMesh& mesh, bool project) : project_(project) {
    const Topology& top = mesh.topology();
    const int nf = top.num_faces();
    x_.reserve(static_cast<size_t>(mesh.num_vertices()) * 4);
    for (int i = 0; i < mesh.num_vertices(); ++i) x_.push_back(mesh.position(i));
    tri_.resize(nf);
    nbr_.resize(nf);
    for (int f = 0; f < nf; ++f) {
      for (int k = 0; k < 3; ++k) {
        tri_[f][k] = top.faces()(f, k);
        const int e = top.face_edges()(f, k);
        const int f0 = top.edge_faces()(e, 0), f1 = top.edge_faces()(e, 1);
        nbr_[f][k] = (f0 == f) ? f1 : f0;
      }
    }
    done_.assign(nf, 0);
  }

  void pass() {
    const int nf = static_cast<int>(tri_.size());
    // Triangles made in this pass (children, kept in the parent's slot or appended) are not
    // visited again; a triangle of the start that was split by propagation counts as done.
    for (int t = 0; t < nf; ++t) {
      if (!done_[t]) bisect_longest(t, 0);
    }
  }

  TriMesh result() const {
    Points x(static_cast<Eigen::Index>(x_.size()), 3);
    for (size_t i = 0; i < x_.size(); ++i) x.row(static_cast<Eigen::Index>(i)) = x_[i].transpose();
    Faces f(static_cast<Eigen::Index>(tri_.size()), 3);
    for (size_t i = 0; i < tri_.size(); ++i)
      for (int k = 0; k < 3; ++k) f(static_cast<Eigen::Index>(i), k) = tri_[i][k];
    return TriMesh(std::move(x), f);
  }

 private:
  // Local index of the longest edge of t (the edge opposite that corner). Lengths equal to a
  // relative 1e-12 are ties, broken by the smaller (sorted) vertex pair, so that both triangles
  // sharing an edge agree on it and the result does not depend on round-off.
  int longest(int t) const {
    const auto& v = tri_[t];
    int best = -1;
    double best_len = 0;
    std::array<int, 2> best_key{};
    for (int k = 0; k < 3; ++k) {
      const int a = v[(k + 1) % 3], b = v[(k + 2) % 3];
      const double len = (x_[a] - x_[b]).squaredNorm();
      const std::array<int, 2> key{std::min(a, b), std::max(a, b)};
      if (best < 0) {
        best = k, best_len = len, best_key = key;
        continue;
      }
      const double tol = 1e-12 * std::max(len, best_len);
      if (len > best_len + tol || (std::abs(len - best_len) <= tol && key < best_key)) {
        best = k, best_len = len, best_key = key;
      }
    }
    return best;
  }

  int local_index_of(int t, int neighbour) const {
    for (int k = 0; k < 3; ++k)
      if (nbr_[t][k] == neighbour) return k;
    throw Error("rivara_pass: broken neighbour links");
  }

  void bisect_longest(int t, int depth) { bisect_at(t, longest(t), depth); }

  // Bisects t at the edge opposite its corner k together with the neighbour across that edge
  // (conforming). When that edge is not the neighbour's longest, the neighbour is first bisected at
  // its own longest edge (recursively); its child that holds the edge is then bisected at it
  // (Rivara 1984). The path of edges followed grows strictly in length, so the recursion ends.
  void bisect_at(int t, int k, int depth) {
    if (depth > static_cast<int>(tri_.size())) throw Error("rivara_pass: propagation does not terminate");
    int u = nbr_[t][k];
    int j = local_index_of(u, t);
    if (longest(u) != j) {
      bisect_longest(u, depth + 1);
      u = nbr_[t][k];
      j = local_index_of(u, t);
    }
    split_pair(t, k, u, j);
  }

  void relink(int outer, int from, int to) {
    nbr_[outer][local_index_of(outer, from)] = to;
  }

  // t = (a, b, c) with the edge b-c opposite corner k; u = (d, c, b) with corner j = d.
  // Children: t1 = (a, b, m) in slot t, t2 = (a, m, c); u1 = (d, c, m) in slot u, u2 = (d, m, b).
  void split_pair(int t, int k, int u, int j) {
    const int a = tri_[t][k], b = tri_[t][(k + 1) % 3], c = tri_[t][(k + 2) % 3];
    const int d = tri_[u][j];
    const int t_ab = nbr_[t][(k + 2) % 3], t_ca = nbr_[t][(k + 1) % 3];
    const int u_dc = nbr_[u][(j + 2) % 3], u_bd = nbr_[u][(j + 1) % 3];

    Vec3 mid = 0.5 * (x_[b] + x_[c]);
    if (project_) mid.normalize();
    const int m = static_cast<int>(x_.size());
    x_.push_back(mid);

    const int t1 = t, u1 = u;
    const int t2 = static_cast<int>(tri_.size()), u2 = t2 + 1;
    tri_.resize(tri_.size() + 2);
    nbr_.resize(nbr_.size() + 2);
    done_.resize(done_.size() + 2, 1);
    done_[t] = done_[u] = 1;

    tri_[t1] = {a, b, m};
    nbr_[t1] = {u2, t2, t_ab};
    tri_[t2] = {a, m, c};
    nbr_[t2] = {u1, t_ca, t1};
    tri_[u1] = {d, c, m};
    nbr_[u1] = {t2, u2, u_dc};
    tri_[u2] = {d, m, b};
    nbr_[u2] = {t1, u_bd, u1};
    relink(t_ca, t, t2);
    relink(u_bd, u, u2);
  }

  bool project_;
  std::vector<Vec3> x_;
  std::vector<std::array<int, 3>> tri_, nbr_;
  std::vector<char> done_;
};

}  // namespace

TriMesh rivara_pass(const TriMesh& mesh, bool project_to_unit_sphere) {
  Bisector b(mesh, project_to_unit_sphere);
  b.pass();
  return b.result();
}

void check_sphere_mesh_arguments(int level, int rivara_passes, const std::string& level_name,
                                 const std::string& rivara_name) {
  if (level < 0 || level > 8) throw Error(level_name + " must be 0..8, got " + std::to_string(level));
  if (rivara_passes < 0 || rivara_passes > 6)
    throw Error(rivara_name + " must be 0..6, got " + std::to_string(rivara_passes));
}

TriMesh sphere_mesh(MeshFamily family, int level, int rivara_passes) {
  check_sphere_mesh_arguments(level, rivara_passes);
  TriMesh m = family == MeshFamily::Octa ? octahedron() : icosahedron();
  if (family == MeshFamily::Irregular) {
    m = irregular_sphere_mesh(level);
  } else {
    for (int k = 0; k < level; ++k) m = family == MeshFamily::MT1 ? refine_loop(m) : refine_midpoint(m);
  }
  for (int p = 0; p < rivara_passes; ++p) m = rivara_pass(m);
  return m;
}

TriMesh irregular_sphere_mesh(int level, double fraction, std::uint64_t base_seed) {
  return jitter_sphere(sphere_mesh(MeshFamily::MT1, level), fraction, base_seed + static_cast<std::uint64_t>(level));
}

int level_with_triangles(MeshFamily family, long triangles) {
  const long base = family == MeshFamily::Octa ? 8 : 20;
  for (int level = 0; level <= 12; ++level)
    if (base << (2 * level) == triangles) return level;
  return -1;
}

}  // namespace bendlab
