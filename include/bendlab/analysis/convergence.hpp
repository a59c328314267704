#pragma once
// Convergence rates of error measures under mesh refinement, and the symbols of the paper's
// tables 2 and 3 derived from them.
//
// Rate: the least-squares slope s of log(error) against log(1/h), h = mean edge length. An error
// that behaves as C h^p has s = -p: s < 0 converges, s > 0 diverges.
//
// Table 2 (per family, method, quantity, measure), from the finest meshes of the series, sorted
// by decreasing h:
//   s_tail = fitted slope over the last `tail_points` points (3 by default; all if fewer),
//   s_last = slope between the last two points.
//   ●  converges to zero:        s_tail <= -0.5 and s_last <= -0.5   (at least ~h^0.5 on both)
//   ■  diverges:                  s_tail >= +0.25 or s_last >= +0.25 (the error grows by 19 % or
//                                 more per halving of h)
//   ○  systematic error:         otherwise (the decrease stalls or the error stays level)
//   an error that is below `exact_error` on every tail point counts as ●.
//   Fewer than two usable points (positive, finite errors) give "undetermined" (shown as –).
//
// Table 3 (inhomogeneous mesh): the inhomogeneous mesh's max and average errors are compared with
// those of the homogeneous family it came from at the same h, interpolated linearly in log-log
// between the two homogeneous meshes that bracket its h (extrapolated from the two nearest when
// none bracket it). With ratios r_max, r_avg (inhomogeneous / homogeneous) and a factor F (2):
//   ●  no troubles:               r_max < F and r_avg < F
//   ○  only the maximum worse:    r_max >= F and r_avg < F
//   ■  the average worse:         r_avg >= F (in the paper's cells with ■ both are worse)
#include <string>
#include <vector>

namespace bendlab {

/// One line of errors.csv.
struct ErrorRow {
  std::string family;  ///< "mt1", "mt2", "octa", "rivara-mt1", "rivara-mt2"
  int triangles = 0;
  double h = 0;        ///< mean edge length of the mapped (RBC) mesh
  std::string method;
  std::string quantity;  ///< "n", "H", "K", "lapH", "f"
  double max_error = 0, avg_error = 0;
};

/// Least-squares slope of log(error) against log(1/h). NaN with fewer than two points, or when a
/// point has a non-positive or non-finite h or error, or all h are equal.
double loglog_slope(const std::vector<double>& h, const std::vector<double>& error);

enum class Trend { ToZero, Systematic, Diverges, Undetermined };
/// "●", "○", "■", "–".
std::string symbol(Trend t);
/// "to zero", "systematic", "diverges", "undetermined".
std::string to_string(Trend t);

struct ConvergenceThresholds {
  int tail_points = 3;
  double to_zero_slope = -0.5;
  double diverge_slope = 0.25;
  double exact_error = 1e-12;
};

struct TrendFit {
  int points = 0;            ///< usable points in the series
  double slope_all = 0;      ///< fit over all points
  double slope_tail = 0;     ///< fit over the last tail_points
  double slope_last = 0;     ///< last two points
  Trend trend = Trend::Undetermined;
};

/// Classifies one series (any order of points; sorted here by decreasing h).
TrendFit classify_convergence(const std::vector<double>& h, const std::vector<double>& error,
                              const ConvergenceThresholds& thresholds = {});

struct RateFit {
  std::string family, method, quantity;
  std::string measure;  ///< "max" or "avg"
  std::vector<int> triangles;
  std::vector<double> h, error;  ///< by decreasing h
  TrendFit fit;
};

/// One RateFit per (family, method, quantity, measure) present in rows for the given families,
/// in the order of first appearance.
std::vector<RateFit> fit_rates(const std::vector<ErrorRow>& rows, const std::vector<std::string>& families,
                               const ConvergenceThresholds& thresholds = {});

/// Piecewise-linear interpolation in log-log of error(h) at h0 (see the header comment). NaN with
/// fewer than two usable points.
double interpolate_loglog(const std::vector<double>& h, const std::vector<double>& error, double h0);

enum class Trouble { None, MaxOnly, Severe, Undetermined };
/// "●", "○", "■", "–".
std::string symbol(Trouble t);

struct InhomogeneityThresholds {
  double factor = 2.0;
};

struct InhomogeneityCheck {
  std::string family, origin, method, quantity;
  int triangles = 0;
  double h = 0;
  double max_error = 0, avg_error = 0;  ///< of the inhomogeneous mesh
  double ref_max = 0, ref_avg = 0;      ///< homogeneous reference at the same h
  double ratio_max = 0, ratio_avg = 0;
  Trouble trouble = Trouble::Undetermined;
};

/// Compares each row of `family` (an inhomogeneous mesh) with the homogeneous `origin` family.
std::vector<InhomogeneityCheck> compare_inhomogeneous(const std::vector<ErrorRow>& rows, const std::string& family,
                                                      const std::string& origin,
                                                      const InhomogeneityThresholds& thresholds = {});

}  // namespace bendlab
