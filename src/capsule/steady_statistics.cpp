#include "bendlab/capsule/steady_statistics.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "bendlab/core/types.hpp"

namespace bendlab {

SteadyWindow SteadyWindow::for_run(double t_end) { return t_end >= 10 ? SteadyWindow{5, 10} : SteadyWindow{t_end / 2, t_end}; }

bool SteadyWindow::contains(double t) const { return !(t < begin || t > end + 1e-12); }

void SteadyStatistics::add(const TimeSeriesRow& r) {
  if (!window_.contains(r.t)) return;
  D_dt_ += r.D * r.dt;
  theta_dt_ += r.theta * r.dt;
  weight_ += r.dt;
  dt_sum_ += r.dt;
  ++count_;
}

double SteadyStatistics::D() const { return weight_ > 0 ? D_dt_ / weight_ : std::numeric_limits<double>::quiet_NaN(); }
double SteadyStatistics::theta() const {
  return weight_ > 0 ? theta_dt_ / weight_ : std::numeric_limits<double>::quiet_NaN();
}
double SteadyStatistics::mean_dt() const {
  return count_ > 0 ? dt_sum_ / static_cast<double>(count_) : std::numeric_limits<double>::quiet_NaN();
}

nlohmann::json SteadyStatistics::to_json() const {
  return {{"window", {window_.begin, window_.end}}, {"weight", weight_}, {"D_dt", D_dt_}, {"theta_dt", theta_dt_},
          {"dt_sum", dt_sum_}, {"count", count_}};
}

SteadyStatistics SteadyStatistics::from_json(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object()) throw Error(fmt::format("{}: expected an object of running sums", where));
  auto number = [&](const char* key) {
    if (!j.contains(key) || !j.at(key).is_number())
      throw Error(fmt::format("{}: key \"{}\" missing or not a number", where, key));
    const double v = j.at(key).get<double>();
    if (!std::isfinite(v)) throw Error(fmt::format("{}: \"{}\" is not finite", where, key));
    return v;
  };
  const auto& w = j.contains("window") ? j.at("window") : nlohmann::json();
  if (!w.is_array() || w.size() != 2 || !w[0].is_number() || !w[1].is_number() || !(w[0].get<double>() <= w[1].get<double>()))
    throw Error(fmt::format("{}: \"window\" must be [begin, end] with begin <= end", where));
  SteadyStatistics s({w[0].get<double>(), w[1].get<double>()});
  s.weight_ = number("weight");
  s.D_dt_ = number("D_dt");
  s.theta_dt_ = number("theta_dt");
  s.dt_sum_ = number("dt_sum");
  if (!j.contains("count") || !j.at("count").is_number_integer() || j.at("count").get<std::int64_t>() < 0)
    throw Error(fmt::format("{}: \"count\" must be a non-negative integer", where));
  s.count_ = j.at("count").get<std::int64_t>();
  if (s.weight_ < 0 || s.dt_sum_ < 0 || (s.count_ == 0) != (s.weight_ == 0))
    throw Error(fmt::format("{}: running sums are inconsistent (count {}, weight {})", where, s.count_, s.weight_));
  return s;
}

}  // namespace bendlab
