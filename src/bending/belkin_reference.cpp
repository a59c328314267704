// The reference form of BelkinLaplacian (belkin.hpp, neighbours = all): every vertex scans every
// point, in vertex order, one run shared by all; O(N^2), what the grid form is tested against.
#include "bendlab/bending/belkin.hpp"
#include "bendlab/bending/belkin_kernel.hpp"

namespace bendlab {

using namespace belkin_kernel;

// The reference form (run_sum_body): for every vertex i, the sum of eq. (13) over all points.
template <int Cols>
void BelkinLaplacian::apply_columns(const double* const* w, double* const* out, std::vector<double>& ws) const {
  // The fields in the points' (scan) order, so that a run reads contiguous memory.
  // Each column padded by kLanes zeros (the kernel reads whole blocks).
  const std::size_t stride = static_cast<std::size_t>(n_) + kLanes;
  ws.assign(static_cast<std::size_t>(Cols) * stride, 0.0);
  for (int col = 0; col < Cols; ++col)
    for (int k = 0; k < n_; ++k) ws[col * stride + k] = w[col][order_[k]];
  KernelInput in{};
  in.sx = point_array(0), in.sy = point_array(1), in.sz = point_array(2), in.sn = point_array(3);
  in.sl = point_array(4);
  for (int col = 0; col < 3; ++col) in.w[col] = ws.data() + (col < Cols ? col : 0) * stride;
  in.emax = max_exponent_;
  in.half_space = options_.half_space;
#pragma omp parallel for schedule(dynamic, 64) firstprivate(in)
  for (int i = 0; i < n_; ++i) {
    in.xi = qx_[i], in.yi = qy_[i], in.zi = qz_[i];
    in.margin = kPlaneTolerance * qnorm_[i];
    const double a = kernel_area_[i];
    in.inv4a = 1.0 / (4.0 * a);
    for (int col = 0; col < 3; ++col) in.wi[col] = w[col < Cols ? col : 0][i];
    double acc[3] = {0, 0, 0};
    const int r0 = run_shared_ ? 0 : run_start_[i], r1 = run_shared_ ? 2 : run_start_[i + 1];
    if constexpr (Cols == 1)
      run_sum1(in, runs_.data() + r0, (r1 - r0) / 2, acc);
    else
      run_sum3(in, runs_.data() + r0, (r1 - r0) / 2, acc);
    const double scale = 1.0 / (4.0 * M_PI * a * a);  // eq. (13) prefactor
    for (int col = 0; col < Cols; ++col) out[col][i] = scale * acc[col];
  }
}

template void BelkinLaplacian::apply_columns<1>(const double* const*, double* const*, std::vector<double>&) const;
template void BelkinLaplacian::apply_columns<3>(const double* const*, double* const*, std::vector<double>&) const;

}  // namespace bendlab
