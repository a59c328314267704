#include "bendlab/flow/suspension_recorder.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <regex>

#include "bendlab/capsule/capsule_shape.hpp"
#include "bendlab/capsule/checkpoint.hpp"
#include "bendlab/core/atomic_file.hpp"
#include "bendlab/flow/lbm/wall_stress.hpp"
#include "bendlab/suspension/flow_measures.hpp"

namespace fs = std::filesystem;

namespace bendlab {

namespace {

constexpr const char* kSeries = "timeseries.csv";
constexpr const char* kCells = "cells.csv";
constexpr const char* kProfiles = "profiles.csv";

// The series' columns whose steady means go into the summary, with their keys.
struct SummaryColumn {
  const char* key;
  std::size_t column;
};
constexpr SummaryColumn kSummaryColumns[] = {{"mean_velocity_um_s", 3},   {"apparent_viscosity", 4},
                                             {"tube_hematocrit", 5},      {"discharge_hematocrit", 6},
                                             {"cell_free_layer_um", 7}};

nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

std::vector<double> json_numbers(const nlohmann::json& j, std::size_t n, const std::string& what) {
  if (!j.is_array() || j.size() != n) throw Error(fmt::format("{} must be an array of {} numbers", what, n));
  std::vector<double> v(n);
  for (std::size_t k = 0; k < n; ++k) {
    if (!j[k].is_number() || !std::isfinite(j[k].get<double>()))
      throw Error(fmt::format("{} entry {} is {}, expected a finite number", what, k, j[k].dump()));
    v[k] = j[k].get<double>();
  }
  return v;
}

// Visits every line of fluid nodes along x, (j, k) in index order, with the sum of u_x along it;
// returns the sum over all lines. The flow rate and the velocity profile share it, so that Q0 of
// the cell-free flow and Q of a run without cells are summed alike, bit for bit.
template <class Visit>
double sum_lines(const lbm::Lattice& lattice, Visit&& visit) {
  double flux = 0;
  const int nx = lattice.nx();
  for (int k = 0; k < lattice.nz(); ++k)
    for (int j = 0; j < lattice.ny(); ++j) {
      if (lattice.solid_row(j, k)) continue;
      double line = 0;
      for (int i = 0; i < nx; ++i) line += lattice.velocity(lattice.index(i, j, k)).x();
      flux += line;
      visit(j, k, line);
    }
  return flux;
}

}  // namespace

double lattice_flow_rate(const lbm::Lattice& lattice, double dx_um, double dt_seconds) {
  const double flux = sum_lines(lattice, [](int, int, double) {});
  return flux / lattice.nx() * dx_um * dx_um * dx_um / dt_seconds;
}

MeanWithError mean_with_error(const std::vector<double>& values) {
  MeanWithError m;
  m.rows = static_cast<std::int64_t>(values.size());
  if (values.empty()) return {kNaN, kNaN, 0};
  auto mean_of = [](const double* v, std::size_t n) {
    double s = 0;
    for (std::size_t k = 0; k < n; ++k) s += v[k];
    return s / static_cast<double>(n);
  };
  auto error_of = [](const std::vector<double>& v, double mean) {
    if (v.size() < 2) return kNaN;
    double s = 0;
    for (double x : v) s += (x - mean) * (x - mean);
    return std::sqrt(s / static_cast<double>(v.size() - 1) / static_cast<double>(v.size()));
  };
  m.mean = mean_of(values.data(), values.size());
  if (values.size() < 20) {
    m.standard_error = error_of(values, m.mean);
    return m;
  }
  // Ten batches of equal length (the first rows beyond a multiple of ten are left out of the
  // batches, not of the mean).
  constexpr std::size_t kBatches = 10;
  const std::size_t length = values.size() / kBatches, skip = values.size() - kBatches * length;
  std::vector<double> batch(kBatches);
  for (std::size_t b = 0; b < kBatches; ++b) batch[b] = mean_of(values.data() + skip + b * length, length);
  m.standard_error = error_of(batch, mean_of(batch.data(), kBatches));
  return m;
}

const char* SuspensionRecorder::series_header() {
  return "t_s,dt_s,flow_rate_um3_s,mean_velocity_um_s,apparent_viscosity,tube_hematocrit,discharge_hematocrit,"
         "cell_free_layer_um";
}

const char* SuspensionRecorder::cells_header() { return "t_s,cell,x_um,y_um,z_um,u_um_s,D,axis_angle_deg"; }

SuspensionRecorder::SuspensionRecorder(const LbmSuspensionSolver& solver, SuspensionRecorderOptions options)
    : solver_(solver), options_(std::move(options)), shear_box_(solver.suspension().lattice().shear_rate() > 0) {
  if (!shear_box_ && (!(options_.reference_flow_rate > 0) || !std::isfinite(options_.reference_flow_rate)))
    throw Error(fmt::format("suspension recorder: the cell-free flow rate {} must be positive",
                            options_.reference_flow_rate));
  if (!(options_.slice_width_um > 0) || !std::isfinite(options_.slice_width_um))
    throw Error("suspension recorder: the slice width must be positive");
  if (!(options_.steady_from >= 0 && options_.steady_from < 1))
    throw Error(fmt::format("suspension recorder: the steady window's start {} must lie in [0, 1)", options_.steady_from));
  // Bins across the section, one dx wide, for the lines of lattice nodes along x.
  const lbm::Lattice& lattice = solver_.suspension().lattice();
  const double dx = solver_.options().dx_um;
  const Vessel& v = options_.vessel_um;
  bin_of_line_.assign(static_cast<std::size_t>(lattice.ny()) * lattice.nz(), -1);
  int bins = 0;
  for (int k = 0; k < lattice.nz(); ++k)
    for (int j = 0; j < lattice.ny(); ++j) {
      if (lattice.solid_row(j, k)) continue;
      const Vec3 p = lattice.position(0, j, k) * dx;
      if (v.wall_distance(p) <= 0) continue;
      const double across = v.kind() == VesselKind::Tube ? std::hypot(p.y(), p.z()) : p.z() + 0.5 * v.height();
      const int bin = static_cast<int>(std::floor(across / dx));
      bin_of_line_[static_cast<std::size_t>(j) + static_cast<std::size_t>(lattice.ny()) * k] = bin;
      bins = std::max(bins, bin + 1);
    }
  bin_lines_.assign(static_cast<std::size_t>(bins), 0.0);
  for (int bin : bin_of_line_)
    if (bin >= 0) bin_lines_[static_cast<std::size_t>(bin)] += 1;
  velocity_sum_.assign(bin_lines_.size(), 0.0);
  hematocrit_sum_.assign(bin_lines_.size(), 0.0);
}

bool SuspensionRecorder::is_output(const std::string& name) const {
  static const std::regex slice_re(R"(fluid_\d{5,}\.vtk)");
  return name == kSeries || name == kCells || name == kProfiles || std::regex_match(name, slice_re);
}

void SuspensionRecorder::snapshot(const fs::path& folder, const std::string& tag) {
  const lbm::Lattice& lattice = solver_.suspension().lattice();
  const double dx = solver_.options().dx_um, dt = solver_.options().dt_seconds;
  const int j = lattice.ny() / 2;  // the node row nearest y = 0 (y = 1/2 dx for an even ny)
  AtomicFile f(folder / fmt::format("fluid_{}.vtk", tag));
  std::ostream& out = f.stream();
  const Vec3 origin = lattice.position(0, j, 0) * dx;
  out << "# vtk DataFile Version 3.0\n"
      << fmt::format("bendlab fluid slice y = {:.6g} um at t = {:.9g} s\n", origin.y(), solver_.time())
      << "ASCII\nDATASET STRUCTURED_POINTS\n"
      << fmt::format("DIMENSIONS {} 1 {}\nORIGIN {:.9g} {:.9g} {:.9g}\nSPACING {:.9g} {:.9g} {:.9g}\n", lattice.nx(),
                     lattice.nz(), origin.x(), origin.y(), origin.z(), dx, dx, dx)
      << fmt::format("POINT_DATA {}\nVECTORS velocity_um_s double\n", lattice.nx() * lattice.nz());
  for (int k = 0; k < lattice.nz(); ++k)
    for (int i = 0; i < lattice.nx(); ++i) {
      const Vec3 u = lattice.velocity(lattice.index(i, j, k)) * (dx / dt);
      out << fmt::format("{:.9g} {:.9g} {:.9g}\n", u.x(), u.y(), u.z());
    }
  out << "SCALARS density_lattice double 1\nLOOKUP_TABLE default\n";
  for (int k = 0; k < lattice.nz(); ++k)
    for (int i = 0; i < lattice.nx(); ++i) out << fmt::format("{:.12g}\n", lattice.density(lattice.index(i, j, k)));
  f.commit();
}

void SuspensionRecorder::start(const fs::path& folder, double t_end, bool writes_files) {
  t_end_ = t_end;
  if (!writes_files) return;
  series_.emplace(RowFile::create(folder / kSeries, series_header()));
  cells_.emplace(RowFile::create(folder / kCells, cells_header()));
}

double SuspensionRecorder::check_resume(const fs::path& folder, const CapsuleCheckpoint& saved, double t_end,
                                        bool writes_files, const std::string& source) {
  t_end_ = t_end;
  double largest = 0;
  if (writes_files) {
    const std::vector<NumberRow> rows = RowFile::read_head(folder / kSeries, series_header(), saved.steps);
    for (const NumberRow& r : rows) largest = std::max(largest, r[1]);
    if (!rows.empty() && std::abs(rows.back()[0] - saved.time) > 1e-9 * std::max(1.0, std::abs(saved.time)))
      throw Error(fmt::format("{}: \"time\" is {} and \"steps\" {}, but row {} of '{}' is at t = {} s", source,
                              saved.time, saved.steps, rows.size(), (folder / kSeries).string(), rows.back()[0]));
    RowFile::read_head(folder / kCells, cells_header(), saved.steps * solver_.suspension().num_cells());
  }
  const auto& r = saved.recorder;
  if (!r.contains("profiles") || !r.at("profiles").is_object())
    throw Error(fmt::format("{}: \"profiles\" must be an object", source));
  const auto& p = r.at("profiles");
  const std::string what = source + ": \"profiles\"";
  json_numbers(p.value("velocity_sum", nlohmann::json()), bin_lines_.size(), what + " velocity_sum");
  json_numbers(p.value("hematocrit_sum", nlohmann::json()), bin_lines_.size(), what + " hematocrit_sum");
  if (!p.contains("samples") || !p.at("samples").is_number_integer() || p.at("samples").get<std::int64_t>() < 0 ||
      p.at("samples").get<std::int64_t>() > saved.steps)
    throw Error(fmt::format("{} \"samples\" must be an integer in [0, steps]", what));
  saved_profiles_ = p;
  return largest;
}

void SuspensionRecorder::resume(const fs::path& folder, const CapsuleCheckpoint& saved, double t_end,
                                bool writes_files, const std::function<void(const std::string&)>& note) {
  if (!saved_profiles_) throw Error("suspension recorder: resume without check_resume");
  t_end_ = t_end;
  const nlohmann::json& p = *saved_profiles_;
  velocity_sum_ = json_numbers(p.at("velocity_sum"), bin_lines_.size(), "velocity_sum");
  hematocrit_sum_ = json_numbers(p.at("hematocrit_sum"), bin_lines_.size(), "hematocrit_sum");
  profile_samples_ = p.at("samples").get<std::int64_t>();
  const bool window_moved = p.contains("t_end") && p.at("t_end").is_number() &&
                            std::abs(p.at("t_end").get<double>() - t_end) > 1e-12 * t_end;
  saved_profiles_.reset();  // p dangles from here on
  if (window_moved && note)
    note("t_end moved the steady window: the profiles keep the samples of the old window, the summary's means are "
         "taken from timeseries.csv over the new one");
  if (!writes_files) return;
  series_.emplace(RowFile::resume(folder / kSeries, series_header(), saved.steps));
  cells_.emplace(RowFile::resume(folder / kCells, cells_header(), saved.steps * solver_.suspension().num_cells()));
}

void SuspensionRecorder::record(const AcceptedStep& s) {
  const lbm::LbmSuspension& susp = solver_.suspension();
  const lbm::Lattice& lattice = susp.lattice();
  const double dx = solver_.options().dx_um, dt = solver_.options().dt_seconds;
  const Points& x = *s.positions;
  const bool in_window = s.time >= options_.steady_from * t_end_ - 1e-12;

  // The flow rate, and the velocity profile in the window.
  const int nx = lattice.nx();
  const double flux = sum_lines(lattice, [&](int j, int k, double line) {
    const int bin = bin_of_line_[static_cast<std::size_t>(j) + static_cast<std::size_t>(lattice.ny()) * k];
    if (in_window && bin >= 0) velocity_sum_[static_cast<std::size_t>(bin)] += line / nx * dx / dt;
  });
  const double Q = flux / nx * dx * dx * dx / dt;  // um^3/s, as lattice_flow_rate
  const Vessel& v = options_.vessel_um;
  const double area = v.volume() / v.length();

  // The cells.
  CellRows rows;
  const int cells = susp.num_cells();
  const Points U = susp.velocities() * (dx / dt);  // um/s
  for (int c = 0; c < cells; ++c) {
    const Eigen::Index first = susp.first_row(c), count = susp.rows(c);
    const Points xc = x.middleRows(first, count);
    const CapsuleShape shape = capsule_shape(susp.membrane(c).topology(), xc);
    rows.first.push_back(first);
    rows.count.push_back(count);
    rows.volume.push_back(shape.volume);
    rows.topology.push_back(&susp.membrane(c).topology());
    if (cells_) {
      const double u = U.middleRows(first, count).col(0).mean();
      const double angle = std::acos(std::min(1.0, std::abs(shape.short_axis.x()))) * 180.0 / M_PI;
      cells_->append({s.time, static_cast<double>(c), shape.centroid.x(), shape.centroid.y(), shape.centroid.z(), u,
                      shape.D, angle});
    }
  }
  const double H_T = cells ? tube_hematocrit(v, rows) : 0.0;
  // The shear box carries no net flux through a cross-section: no discharge hematocrit, and the
  // viscosity from the walls' stress instead of the flow rate.
  const double H_D = shear_box_ ? kNaN : cells ? discharge_hematocrit(v, rows, U, Q) : 0.0;
  const double cfl = cells ? cell_free_layer(v, x, options_.slice_width_um) : kNaN;
  const double eta = shear_box_ ? lbm::wall_shear_stress(lattice) / (lattice.viscosity() * lattice.shear_rate())
                                : options_.reference_flow_rate / Q;
  last_ = {s.time, s.dt, Q, Q / area, eta, H_T, H_D, cfl};
  if (series_) series_->append(last_);

  if (in_window) {
    if (cells) {
      LineGrid grid;
      grid.y0 = lattice.position(0, 0, 0).y() * dx;
      grid.z0 = lattice.position(0, 0, 0).z() * dx;
      grid.dy = grid.dz = dx;
      grid.ny = lattice.ny();
      grid.nz = lattice.nz();
      const std::vector<double> occupancy = row_occupancy(v, rows, x, grid);
      for (std::size_t line = 0; line < occupancy.size(); ++line)
        if (bin_of_line_[line] >= 0) hematocrit_sum_[static_cast<std::size_t>(bin_of_line_[line])] += occupancy[line];
    }
    ++profile_samples_;
  }
}

ProgressMeasures SuspensionRecorder::progress() const {
  if (last_.empty()) return {};
  return {{"eta_app", last_[4]}, {"H_D", last_[6]}, {"CFL_um", last_[7]}};
}

nlohmann::json SuspensionRecorder::state() const {
  return {{"profiles",
           {{"velocity_sum", velocity_sum_},
            {"hematocrit_sum", hematocrit_sum_},
            {"samples", profile_samples_},
            {"t_end", t_end_}}}};
}

nlohmann::json SuspensionRecorder::summary(const fs::path& folder, double t_end, const Points& positions) const {
  (void)positions;
  const std::vector<NumberRow> rows = RowFile::read_all(folder / kSeries, series_header());
  const double begin = options_.steady_from * t_end;
  nlohmann::json fields;
  std::int64_t window_rows = 0;
  for (const SummaryColumn& col : kSummaryColumns) {
    std::vector<double> values;
    for (const NumberRow& r : rows)
      if (r[0] >= begin - 1e-12 && std::isfinite(r[col.column])) values.push_back(r[col.column]);
    const MeanWithError m = mean_with_error(values);
    fields[col.key] = {{"mean", finite_or_null(m.mean)},
                       {"standard_error", finite_or_null(m.standard_error)},
                       {"rows", m.rows}};
    window_rows = std::max(window_rows, m.rows);
  }
  fields["steady_window_s"] = {begin, t_end};
  fields["steady_rows"] = window_rows;
  fields["cells"] = solver_.suspension().num_cells();
  if (shear_box_) {
    fields["shear_rate_1_s"] = solver_.suspension().lattice().shear_rate() / solver_.options().dt_seconds;
  } else {
    fields["reference_flow_rate_um3_s"] = options_.reference_flow_rate;
  }
  // The profiles of the window.
  AtomicFile f(folder / kProfiles);
  f.stream() << (options_.vessel_um.kind() == VesselKind::Tube ? "r_um" : "z_um")
             << ",velocity_um_s,hematocrit,lines\n";
  const double dx = solver_.options().dx_um;
  const double z0 = options_.vessel_um.kind() == VesselKind::Tube ? 0.0 : -0.5 * options_.vessel_um.height();
  for (std::size_t b = 0; b < bin_lines_.size(); ++b) {
    const double n = bin_lines_[b] * static_cast<double>(profile_samples_);
    f.stream() << fmt::format("{:.12g},{:.12g},{:.12g},{}\n", z0 + (static_cast<double>(b) + 0.5) * dx,
                              n > 0 ? velocity_sum_[b] / n : kNaN, n > 0 ? hematocrit_sum_[b] / n : kNaN,
                              bin_lines_[b]);
  }
  f.commit();
  return fields;
}

}  // namespace bendlab
