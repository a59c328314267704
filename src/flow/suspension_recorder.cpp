#include "bendlab/flow/suspension_recorder.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <regex>

#include "bendlab/capsule/capsule_shape.hpp"
#include "bendlab/capsule/checkpoint.hpp"
#include "bendlab/core/atomic_file.hpp"
#include "bendlab/flow/lbm/diagnostics.hpp"
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

}  // namespace

double lattice_flow_rate(const lbm::Lattice& lattice, double dx_um, double dt_seconds) {
  // The lines in index order, as the recorder adds them: Q0 and Q of a run without cells are
  // summed alike, bit for bit.
  double flux = 0;
  for (double line : lbm::line_velocity_sums(lattice)) flux += line;
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

SuspensionRecorder::SuspensionRecorder(const SuspensionSolver& solver, SuspensionRecorderOptions options)
    : solver_(solver), options_(std::move(options)), shear_box_(solver.shear_rate() > 0) {
  if (!shear_box_ && (!(options_.reference_flow_rate > 0) || !std::isfinite(options_.reference_flow_rate)))
    throw Error(fmt::format("suspension recorder: the cell-free flow rate {} must be positive",
                            options_.reference_flow_rate));
  if (!(options_.slice_width_um > 0) || !std::isfinite(options_.slice_width_um))
    throw Error("suspension recorder: the slice width must be positive");
  if (!(options_.steady_from >= 0 && options_.steady_from < 1))
    throw Error(fmt::format("suspension recorder: the steady window's start {} must lie in [0, 1)", options_.steady_from));
  // Bins across the section, one dx wide, for the lines of lattice nodes along x.
  const lbm::LatticeConfig& lattice = solver_.options().suspension.lattice;
  const double dx = solver_.options().dx_um;
  const Vessel& v = options_.vessel_um;
  bin_of_line_.assign(static_cast<std::size_t>(lattice.ny) * lattice.nz, -1);
  fluid_line_.assign(bin_of_line_.size(), 0);
  int bins = 0;
  for (int k = 0; k < lattice.nz; ++k)
    for (int j = 0; j < lattice.ny; ++j) {
      if (solver_.solid_line(j, k)) continue;
      fluid_line_[static_cast<std::size_t>(j) + static_cast<std::size_t>(lattice.ny) * k] = 1;
      const Vec3 p = solver_.node_position(0, j, k) * dx;
      if (v.wall_distance(p) <= 0) continue;
      const double across = v.kind() == VesselKind::Tube ? std::hypot(p.y(), p.z()) : p.z() + 0.5 * v.height();
      const int bin = static_cast<int>(std::floor(across / dx));
      bin_of_line_[static_cast<std::size_t>(j) + static_cast<std::size_t>(lattice.ny) * k] = bin;
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
  const lbm::LatticeConfig& lattice = solver_.options().suspension.lattice;
  const double dx = solver_.options().dx_um, dt = solver_.options().dt_seconds;
  const int j = lattice.ny / 2;  // the node row nearest y = 0 (y = 1/2 dx for an even ny)
  std::vector<Vec3> velocity;
  std::vector<double> density;
  solver_.layer_fields(j, velocity, density);  // on every process: it may be collective
  if (!writes_files_) return;
  AtomicFile f(folder / fmt::format("fluid_{}.vtk", tag));
  std::ostream& out = f.stream();
  const Vec3 origin = solver_.node_position(0, j, 0) * dx;
  const std::size_t nodes = static_cast<std::size_t>(lattice.nx) * lattice.nz;
  out << "# vtk DataFile Version 3.0\n"
      << fmt::format("bendlab fluid slice y = {:.6g} um at t = {:.9g} s\n", origin.y(), solver_.time())
      << "ASCII\nDATASET STRUCTURED_POINTS\n"
      << fmt::format("DIMENSIONS {} 1 {}\nORIGIN {:.9g} {:.9g} {:.9g}\nSPACING {:.9g} {:.9g} {:.9g}\n", lattice.nx,
                     lattice.nz, origin.x(), origin.y(), origin.z(), dx, dx, dx)
      << fmt::format("POINT_DATA {}\nVECTORS velocity_um_s double\n", nodes);
  for (std::size_t n = 0; n < nodes; ++n) {
    const Vec3 u = velocity[n] * (dx / dt);
    out << fmt::format("{:.9g} {:.9g} {:.9g}\n", u.x(), u.y(), u.z());
  }
  out << "SCALARS density_lattice double 1\nLOOKUP_TABLE default\n";
  for (std::size_t n = 0; n < nodes; ++n) out << fmt::format("{:.12g}\n", density[n]);
  f.commit();
}

void SuspensionRecorder::start(const fs::path& folder, double t_end, bool writes_files) {
  t_end_ = t_end;
  writes_files_ = writes_files;
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
    RowFile::read_head(folder / kCells, cells_header(), saved.steps * num_cells());
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
  writes_files_ = writes_files;
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
  cells_.emplace(RowFile::resume(folder / kCells, cells_header(), saved.steps * num_cells()));
}

int SuspensionRecorder::num_cells() const { return static_cast<int>(solver_.bodies().size()); }

void SuspensionRecorder::record(const AcceptedStep& s) {
  const lbm::LatticeConfig& lattice = solver_.options().suspension.lattice;
  const double dx = solver_.options().dx_um, dt = solver_.options().dt_seconds;
  const Points& x = *s.positions;
  const bool in_window = s.time >= options_.steady_from * t_end_ - 1e-12;

  // The flow rate, and the velocity profile in the window: the lines' sums added in index order
  // (lattice_flow_rate's order, so that Q0 and Q of a run without cells are summed alike).
  const int nx = lattice.nx;
  const std::vector<double> lines = solver_.line_velocity_sums();
  double flux = 0;
  for (std::size_t line = 0; line < lines.size(); ++line) {
    if (!fluid_line_[line]) continue;
    flux += lines[line];
    const int bin = bin_of_line_[line];
    if (in_window && bin >= 0) velocity_sum_[static_cast<std::size_t>(bin)] += lines[line] / nx * dx / dt;
  }
  const double Q = flux / nx * dx * dx * dx / dt;  // um^3/s, as lattice_flow_rate
  const Vessel& v = options_.vessel_um;
  const double area = v.volume() / v.length();

  // The cells.
  CellRows rows;
  const std::vector<SolverBody> bodies = solver_.bodies();
  const int cells = static_cast<int>(bodies.size());
  const Points U = solver_.vertex_velocities() * (dx / dt);  // um/s
  for (int c = 0; c < cells; ++c) {
    const Eigen::Index first = bodies[c].first_row, count = bodies[c].membrane->num_vertices();
    const Points xc = x.middleRows(first, count);
    const CapsuleShape shape = capsule_shape(bodies[c].membrane->topology(), xc);
    rows.first.push_back(first);
    rows.count.push_back(count);
    rows.volume.push_back(shape.volume);
    rows.topology.push_back(&bodies[c].membrane->topology());
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
  const double eta = shear_box_ ? solver_.wall_shear_stress() / (solver_.viscosity() * solver_.shear_rate())
                                : options_.reference_flow_rate / Q;
  last_ = {s.time, s.dt, Q, Q / area, eta, H_T, H_D, cfl};
  if (series_) series_->append(last_);

  if (in_window) {
    if (cells) {
      LineGrid grid;
      grid.y0 = solver_.node_position(0, 0, 0).y() * dx;
      grid.z0 = solver_.node_position(0, 0, 0).z() * dx;
      grid.dy = grid.dz = dx;
      grid.ny = lattice.ny;
      grid.nz = lattice.nz;
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
  fields["cells"] = num_cells();
  if (shear_box_) {
    fields["shear_rate_1_s"] = solver_.shear_rate() / solver_.options().dt_seconds;
  } else {
    fields["reference_flow_rate_um3_s"] = options_.reference_flow_rate;
  }
  // The profiles of the window.
  AtomicFile f(folder / kProfiles);
  f.stream() << (options_.vessel_um.kind() == VesselKind::Tube ? "r_um" : "z_um")
             << ",velocity_um_s,hematocrit,lines\n";
  const double dx = solver_.options().dx_um;
  const double z0 = options_.vessel_um.kind() == VesselKind::Tube ? 0.0 : -0.5 * options_.vessel_um.height();
  // A bin without samples (no line of it in the section, or no report in the window) has no mean:
  // an empty field, as RowFile writes an undefined value.
  auto mean = [](double sum, double n) { return n > 0 ? fmt::format("{:.12g}", sum / n) : std::string(); };
  for (std::size_t b = 0; b < bin_lines_.size(); ++b) {
    const double n = bin_lines_[b] * static_cast<double>(profile_samples_);
    f.stream() << fmt::format("{:.12g},{},{},{}\n", z0 + (static_cast<double>(b) + 0.5) * dx,
                              mean(velocity_sum_[b], n), mean(hematocrit_sum_[b], n), bin_lines_[b]);
  }
  f.commit();
  return fields;
}

}  // namespace bendlab
