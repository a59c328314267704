#include "bendlab/analysis/error_measures.hpp"

#include <cmath>
#include <fmt/format.h>
#include <limits>

namespace bendlab {

namespace {

void check_scale(double scale) {
  if (!(scale > 0) || !std::isfinite(scale))
    throw Error(fmt::format("error measure: the normalising maximum must be positive and finite, got {}", scale));
}

// Empty numerical arrays mean "not defined by the method": all-NaN errors of the right length.
template <class A>
bool undefined_or_checked(const A& analytic, const A& numerical, const char* what) {
  if (numerical.rows() == 0) return true;
  if (numerical.rows() != analytic.rows())
    throw Error(fmt::format("error measure: {} has {} values for {} nodes", what, numerical.rows(),
                            analytic.rows()));
  return false;
}
}  // namespace

std::string to_string(Quantity q) {
  switch (q) {
    case Quantity::Normal: return "n";
    case Quantity::H: return "H";
    case Quantity::K: return "K";
    case Quantity::LapH: return "lapH";
    case Quantity::F: return "f";
  }
  return "?";
}

Quantity parse_quantity(const std::string& name) {
  for (Quantity q : kAllQuantities)
    if (to_string(q) == name) return q;
  throw Error(fmt::format("unknown quantity '{}' (expected n, H, K, lapH or f)", name));
}

Scalars normal_errors(const Points& analytic, const Points& numerical) {
  if (undefined_or_checked(analytic, numerical, "the normal")) return Scalars::Constant(analytic.rows(), kNaN);
  return (analytic - numerical).rowwise().norm();
}

Scalars scalar_errors(const Scalars& analytic, const Scalars& numerical, double scale) {
  check_scale(scale);
  if (undefined_or_checked(analytic, numerical, "a scalar field")) return Scalars::Constant(analytic.rows(), kNaN);
  return (analytic - numerical).cwiseAbs() / scale;
}

Scalars vector_errors(const Points& analytic, const Points& numerical, double scale) {
  check_scale(scale);
  if (undefined_or_checked(analytic, numerical, "a vector field")) return Scalars::Constant(analytic.rows(), kNaN);
  return (analytic - numerical).rowwise().norm() / scale;
}

ErrorSummary summarize(const Scalars& e) {
  ErrorSummary s;
  Eigen::Index nan_count = 0;
  for (Eigen::Index i = 0; i < e.size(); ++i)
    if (std::isnan(e[i])) ++nan_count;
  if (e.size() == 0 || nan_count == e.size()) return s;  // not available
  s.available = true;
  if (nan_count > 0) {
    s.max = s.average = kNaN;
    return s;
  }
  s.max = e.maxCoeff();
  s.average = e.mean();
  return s;
}

const Scalars& NodeErrors::operator[](Quantity q) const {
  switch (q) {
    case Quantity::Normal: return n;
    case Quantity::H: return H;
    case Quantity::K: return K;
    case Quantity::LapH: return lapH;
    case Quantity::F: return f;
  }
  throw Error("unknown quantity");
}

NodeErrors node_errors(const SurfaceFields& a, const SurfaceMaxima& m, const BendingResult& r, double kappa_b) {
  // A field that vanishes identically (Lap H and f on a sphere) has no maximum to divide by; its
  // errors are then measured against the scale the field would have on a surface of the same
  // size: max|H| / L^2 for Lap H and 2 |kB| max|H|^3 for f, with L = 1 / max|H|. A maximum below
  // 1e-9 of that scale counts as vanishing.
  const double lap_scale = m.H * m.H * m.H;
  const double f_scale = 2 * std::abs(kappa_b) * lap_scale;
  auto denominator = [](double maximum, double natural) { return maximum > 1e-9 * natural ? maximum : natural; };
  NodeErrors e;
  e.n = normal_errors(a.normal, r.normal);
  e.H = scalar_errors(a.H, r.H, m.H);
  e.K = scalar_errors(a.K, r.K, m.K);
  e.lapH = scalar_errors(a.lapH, r.lapH, denominator(m.lapH, lap_scale));
  e.f = vector_errors(a.f, r.force_density, denominator(m.f, f_scale));
  return e;
}

}  // namespace bendlab
