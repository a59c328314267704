#pragma once
// The files of the static RBC study (bendlab rbc), written from a finished RbcStudyResult:
//
//   errors.csv      family,triangles,h,method,quantity,max_error,avg_error (eq. 17 measures)
//   timings.csv     family,triangles,vertices,h,method,seconds
//   errors.json     the rows, timings, fitted slopes and the cells of tables 2 and 3
//   table2.md       table 2 (convergence on the homogeneous and irregular families) from the fitted rates
//   table3.md       table 3 (the inhomogeneous meshes against their homogeneous family)
//   values_<family>_<triangles>.csv   per node: theta, numerical and exact H, K, Lap H, |f|, errors
//                   (meshes that kept their nodes)
//   errors_<family>_<triangles>_<method>.vtp   per-node errors and values (figure 9)
//
// Every file appears whole or not at all (AtomicFile).
#include <filesystem>
#include <string>
#include <vector>

#include "bendlab/analysis/convergence.hpp"
#include "bendlab/analysis/rbc_study.hpp"

namespace bendlab {

struct RbcReportOptions {
  ConvergenceThresholds convergence;
  InhomogeneityThresholds inhomogeneity;
  /// Families fitted for table 2.
  std::vector<std::string> fitted_families = {"mt1", "mt2", "octa", "irregular"};
  /// The meshes whose per-node errors go to .vtp files (figures 9 and B.22).
  int vtk_triangles = 5120;
  std::vector<std::string> vtk_families = {"mt1", "mt2"};
};

/// Writes the files above into the existing folder `out`; returns their names in writing order.
std::vector<std::string> write_rbc_report(const std::filesystem::path& out, const RbcStudyResult& study,
                                          const RbcReportOptions& options = {});

}  // namespace bendlab
