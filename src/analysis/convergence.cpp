#include "bendlab/analysis/convergence.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <tuple>

#include "bendlab/core/types.hpp"

namespace bendlab {

namespace {

bool usable(double h, double e) { return std::isfinite(h) && h > 0 && std::isfinite(e) && e > 0; }

// Points sorted by decreasing h (increasing resolution).
std::vector<std::size_t> by_decreasing_h(const std::vector<double>& h) {
  std::vector<std::size_t> order(h.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return h[a] > h[b]; });
  return order;
}
}  // namespace

double loglog_slope(const std::vector<double>& h, const std::vector<double>& error) {
  const std::size_t n = std::min(h.size(), error.size());
  if (n < 2 || h.size() != error.size()) return kNaN;
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!usable(h[i], error[i])) return kNaN;
    mx += -std::log(h[i]);
    my += std::log(error[i]);
  }
  mx /= n;
  my /= n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = -std::log(h[i]) - mx, dy = std::log(error[i]) - my;
    sxx += dx * dx;
    sxy += dx * dy;
  }
  if (sxx == 0) return kNaN;
  return sxy / sxx;
}

std::string symbol(Trend t) {
  switch (t) {
    case Trend::ToZero: return "●";
    case Trend::Systematic: return "○";
    case Trend::Diverges: return "■";
    case Trend::Undetermined: return "–";
  }
  return "–";
}

std::string to_string(Trend t) {
  switch (t) {
    case Trend::ToZero: return "to zero";
    case Trend::Systematic: return "systematic";
    case Trend::Diverges: return "diverges";
    case Trend::Undetermined: return "undetermined";
  }
  return "undetermined";
}

TrendFit classify_convergence(const std::vector<double>& h_in, const std::vector<double>& e_in,
                              const ConvergenceThresholds& th) {
  TrendFit fit;
  fit.slope_all = fit.slope_tail = fit.slope_last = kNaN;
  std::vector<double> h, e, h_small, e_small;
  for (std::size_t k : by_decreasing_h(h_in)) {
    if (k >= e_in.size() || !std::isfinite(h_in[k]) || !(h_in[k] > 0) || !std::isfinite(e_in[k]) || e_in[k] < 0)
      continue;
    h.push_back(h_in[k]);
    e.push_back(e_in[k]);
  }
  fit.points = static_cast<int>(h.size());
  if (h.size() < 2) return fit;
  const std::size_t tail = std::min<std::size_t>(h.size(), std::max(2, th.tail_points));
  const std::vector<double> h_tail(h.end() - tail, h.end()), e_tail(e.end() - tail, e.end());
  if (std::all_of(e_tail.begin(), e_tail.end(), [&](double x) { return x <= th.exact_error; })) {
    fit.trend = Trend::ToZero;  // exact up to round-off on the finest meshes: no slope to fit
    return fit;
  }
  fit.slope_all = loglog_slope(h, e);
  fit.slope_tail = loglog_slope(h_tail, e_tail);
  fit.slope_last = loglog_slope({h[h.size() - 2], h.back()}, {e[e.size() - 2], e.back()});
  if (std::isnan(fit.slope_tail) || std::isnan(fit.slope_last)) return fit;
  if (fit.slope_tail >= th.diverge_slope || fit.slope_last >= th.diverge_slope)
    fit.trend = Trend::Diverges;
  else if (fit.slope_tail <= th.to_zero_slope && fit.slope_last <= th.to_zero_slope)
    fit.trend = Trend::ToZero;
  else
    fit.trend = Trend::Systematic;
  return fit;
}

std::vector<RateFit> fit_rates(const std::vector<ErrorRow>& rows, const std::vector<std::string>& families,
                               const ConvergenceThresholds& th) {
  std::vector<RateFit> fits;
  std::map<std::tuple<std::string, std::string, std::string>, std::vector<const ErrorRow*>> groups;
  std::vector<std::tuple<std::string, std::string, std::string>> order;
  for (const ErrorRow& r : rows) {
    if (std::find(families.begin(), families.end(), r.family) == families.end()) continue;
    auto key = std::make_tuple(r.family, r.method, r.quantity);
    auto [it, inserted] = groups.try_emplace(key);
    if (inserted) order.push_back(key);
    it->second.push_back(&r);
  }
  for (const auto& key : order) {
    const auto& g = groups[key];
    std::vector<double> h;
    for (const ErrorRow* r : g) h.push_back(r->h);
    const auto sorted = by_decreasing_h(h);
    for (const char* measure : {"max", "avg"}) {
      RateFit f;
      std::tie(f.family, f.method, f.quantity) = key;
      f.measure = measure;
      for (std::size_t k : sorted) {
        f.triangles.push_back(g[k]->triangles);
        f.h.push_back(g[k]->h);
        f.error.push_back(f.measure == "max" ? g[k]->max_error : g[k]->avg_error);
      }
      f.fit = classify_convergence(f.h, f.error, th);
      fits.push_back(std::move(f));
    }
  }
  return fits;
}

double interpolate_loglog(const std::vector<double>& h_in, const std::vector<double>& e_in, double h0) {
  std::vector<double> h, e;
  for (std::size_t i = 0; i < std::min(h_in.size(), e_in.size()); ++i)
    if (usable(h_in[i], e_in[i])) {
      h.push_back(h_in[i]);
      e.push_back(e_in[i]);
    }
  if (h.size() < 2 || !(h0 > 0)) return kNaN;
  // Sort by increasing h, then pick the segment [k, k+1] that brackets h0, or the nearest one.
  std::vector<std::size_t> order(h.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return h[a] < h[b]; });
  std::size_t k = 0;
  while (k + 2 < order.size() && h[order[k + 1]] < h0) ++k;
  const double x0 = std::log(h[order[k]]), x1 = std::log(h[order[k + 1]]);
  const double y0 = std::log(e[order[k]]), y1 = std::log(e[order[k + 1]]);
  if (x1 == x0) return kNaN;
  const double t = (std::log(h0) - x0) / (x1 - x0);
  return std::exp(y0 + t * (y1 - y0));
}

std::string symbol(Trouble t) {
  switch (t) {
    case Trouble::None: return "●";
    case Trouble::MaxOnly: return "○";
    case Trouble::Severe: return "■";
    case Trouble::Undetermined: return "–";
  }
  return "–";
}

std::vector<InhomogeneityCheck> compare_inhomogeneous(const std::vector<ErrorRow>& rows, const std::string& family,
                                                      const std::string& origin,
                                                      const InhomogeneityThresholds& th) {
  std::vector<InhomogeneityCheck> checks;
  for (const ErrorRow& r : rows) {
    if (r.family != family) continue;
    InhomogeneityCheck c;
    c.family = family;
    c.origin = origin;
    c.method = r.method;
    c.quantity = r.quantity;
    c.triangles = r.triangles;
    c.h = r.h;
    c.max_error = r.max_error;
    c.avg_error = r.avg_error;
    std::vector<double> h, emax, eavg;
    for (const ErrorRow& o : rows)
      if (o.family == origin && o.method == r.method && o.quantity == r.quantity) {
        h.push_back(o.h);
        emax.push_back(o.max_error);
        eavg.push_back(o.avg_error);
      }
    c.ref_max = interpolate_loglog(h, emax, r.h);
    c.ref_avg = interpolate_loglog(h, eavg, r.h);
    c.ratio_max = c.max_error / c.ref_max;
    c.ratio_avg = c.avg_error / c.ref_avg;
    if (std::isfinite(c.ratio_max) && std::isfinite(c.ratio_avg)) {
      if (c.ratio_avg >= th.factor)
        c.trouble = Trouble::Severe;
      else if (c.ratio_max >= th.factor)
        c.trouble = Trouble::MaxOnly;
      else
        c.trouble = Trouble::None;
    }
    checks.push_back(std::move(c));
  }
  return checks;
}

}  // namespace bendlab
