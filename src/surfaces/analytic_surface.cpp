#include "bendlab/surfaces/analytic_surface.hpp"

#include <fmt/format.h>

#include <cmath>

#include "bendlab/surfaces/surface_of_revolution.hpp"

namespace bendlab {

namespace {

void require_length(const std::string& what, double v) {
  if (!(std::isfinite(v) && v > 0.0))
    throw Error(what + " must be positive and finite, got " + std::to_string(v));
}

}  // namespace

SurfaceOffset max_offset(const AnalyticSurface& surface, const Points& x) {
  SurfaceOffset worst;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const double d = surface.offset(row(x, i));
    if (!(d <= worst.max)) {  // NaN counts as the worst
      worst.max = d;
      worst.node = i;
      if (std::isnan(d)) break;
    }
  }
  return worst;
}

void require_nodes_on_surface(const AnalyticSurface& surface, const Points& x, double relative_tolerance) {
  const SurfaceOffset w = max_offset(surface, x);
  const double limit = relative_tolerance * surface.size();
  if (!(w.max <= limit))
    throw Error(fmt::format("the mesh nodes do not lie on the {} surface: node {} is {:.3g} away from it (tolerance "
                            "{:.3g}); compare against the surface the mesh was made for",
                            surface.name(), w.node, w.max, limit));
}

SurfaceFields AnalyticSurface::evaluate(const Points& x, double kappa_b) const {
  const Eigen::Index n = x.rows();
  SurfaceFields out;
  out.normal.resize(n, 3);
  out.f.resize(n, 3);
  out.H.resize(n);
  out.K.resize(n);
  out.lapH.resize(n);
  out.f_normal.resize(n);
#pragma omp parallel for schedule(static)
  for (Eigen::Index i = 0; i < n; ++i) {
    const SurfaceValues v = at(row(x, i), kappa_b);
    out.normal.row(i) = v.normal.transpose();
    out.f.row(i) = v.f.transpose();
    out.H[i] = v.H;
    out.K[i] = v.K;
    out.lapH[i] = v.lapH;
    out.f_normal[i] = v.f_normal;
  }
  return out;
}

std::unique_ptr<AnalyticSurface> make_sphere(double radius) {
  require_length("sphere radius", radius);
  return std::make_unique<SurfaceOfRevolution>("sphere", radius, std::vector<double>{radius},
                                               SurfaceOfRevolution::SphereMap::Scale);
}

std::unique_ptr<AnalyticSurface> make_spheroid(double a, double c) {
  require_length("spheroid half-axis a", a);
  require_length("spheroid half-axis c", c);
  const char* name = a > c ? "oblate" : (a < c ? "prolate" : "spheroid");
  return std::make_unique<SurfaceOfRevolution>(name, a, std::vector<double>{c},
                                               SurfaceOfRevolution::SphereMap::Scale);
}

std::unique_ptr<AnalyticSurface> make_rbc(double radius) {
  require_length("RBC radius", radius);
  // z = cos t * R/2 (C0 + C1 w + C2 w^2), w = sin^2 t = rho^2: eq. (15).
  const double h = 0.5 * radius;
  return std::make_unique<SurfaceOfRevolution>(
      "rbc", radius, std::vector<double>{h * kRbcC0, h * kRbcC1, h * kRbcC2},
      SurfaceOfRevolution::SphereMap::RbcHeight);
}

std::unique_ptr<AnalyticSurface> make_surface(const std::string& name, double radius,
                                              std::vector<double> axes) {
  if (name == "sphere") return make_sphere(radius);
  if (name == "rbc") return make_rbc(radius);
  if (name == "oblate" || name == "prolate" || name == "spheroid") {
    if (axes.empty()) {
      if (name == "oblate") axes = {1.0, 0.5};
      else if (name == "prolate") axes = {0.5, 1.0};
      else throw Error("surface 'spheroid' needs its two half-axes a, c");
    }
    if (axes.size() != 2)
      throw Error("surface '" + name + "' takes two half-axes a, c, got " +
                  std::to_string(axes.size()));
    require_length(name + " half-axis a", axes[0]);
    require_length(name + " half-axis c", axes[1]);
    if (name == "oblate" && !(axes[0] > axes[1]))
      throw Error("an oblate spheroid needs a > c");
    if (name == "prolate" && !(axes[0] < axes[1]))
      throw Error("a prolate spheroid needs a < c");
    return make_spheroid(axes[0], axes[1]);
  }
  throw Error("unknown surface '" + name + "' (known: sphere, rbc, oblate, prolate, spheroid)");
}

}  // namespace bendlab
