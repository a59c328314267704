#include "bendlab/integrate/anderson_mixing.hpp"

#include <fmt/format.h>

#include "bendlab/core/types.hpp"

namespace bendlab {

AndersonMixing::AndersonMixing(int depth) : depth_(depth) {
  if (depth < 1) throw Error(fmt::format("Anderson mixing: depth {} must be at least 1", depth));
}

void AndersonMixing::reset() {
  count_ = next_ = 0;
  has_prev_ = false;
}

void AndersonMixing::step(const Eigen::VectorXd& x, const Eigen::VectorXd& f, Eigen::VectorXd& dx) {
  if (x.size() != f.size()) throw Error("Anderson mixing: x and f differ in size");
  if (has_prev_ && x_prev_.size() != x.size()) reset();
  if (!has_prev_ || dx_.rows() != x.size()) {
    dx_.resize(x.size(), depth_);
    df_.resize(x.size(), depth_);
  }
  if (has_prev_) {
    dx_.col(next_) = x - x_prev_;
    df_.col(next_) = f - f_prev_;
    next_ = (next_ + 1) % depth_;
    if (count_ < depth_) ++count_;
  }
  x_prev_ = x;
  f_prev_ = f;
  has_prev_ = true;
  if (count_ == 0) {
    dx = f;
    return;
  }
  // The least-squares problem by column-pivoting QR: the columns of dF become nearly dependent as
  // the iteration converges, and the pivoting leaves the dependent ones out instead of amplifying
  // round-off (the order of the columns does not matter to the minimum).
  const auto dF = df_.leftCols(count_);
  const Eigen::VectorXd gamma = dF.colPivHouseholderQr().solve(f);
  if (!gamma.allFinite()) {
    reset();
    x_prev_ = x;
    f_prev_ = f;
    has_prev_ = true;
    dx = f;
    return;
  }
  dx = f - (dx_.leftCols(count_) + dF) * gamma;
}

}  // namespace bendlab
