#pragma once
// Truncated Taylor series ("jets") for exact derivatives of closed-form expressions.
//
// Jet<N> holds the coefficients c[0..N] of f(t0 + h) = sum_k c[k] h^k. Arithmetic on jets is the
// arithmetic of the series truncated after h^N, so evaluating an expression on the jet
// (t0, 1, 0, ...) yields its Taylor coefficients at t0 to rounding error: the k-th derivative is
// k! c[k]. No step size is involved (unlike finite differences).
#include <array>
#include <cmath>

namespace bendlab {

template <int N>
struct Jet {
  static_assert(N >= 0);
  std::array<double, N + 1> c{};

  static Jet constant(double v) {
    Jet j;
    j.c[0] = v;
    return j;
  }
  /// The series of sin(t0 + h) and cos(t0 + h), given s = sin t0 and c = cos t0 (passing the pair
  /// instead of t0 keeps full relative accuracy near t0 = pi, where t0 itself is rounded).
  static void sin_cos(double s, double co, Jet& sin_jet, Jet& cos_jet) {
    // d^k/dt^k sin = sin(t + k pi/2): the values cycle s, co, -s, -co.
    const double cyc_s[4] = {s, co, -s, -co};
    const double cyc_c[4] = {co, -s, -co, s};
    double inv_fact = 1.0;
    for (int k = 0; k <= N; ++k) {
      if (k > 0) inv_fact /= k;
      sin_jet.c[k] = cyc_s[k % 4] * inv_fact;
      cos_jet.c[k] = cyc_c[k % 4] * inv_fact;
    }
  }

  double value() const { return c[0]; }
  /// k-th derivative at t0.
  double derivative(int k) const {
    double f = 1.0;
    for (int i = 2; i <= k; ++i) f *= i;
    return f * c[k];
  }

  Jet& operator+=(const Jet& o) {
    for (int k = 0; k <= N; ++k) c[k] += o.c[k];
    return *this;
  }
  Jet& operator-=(const Jet& o) {
    for (int k = 0; k <= N; ++k) c[k] -= o.c[k];
    return *this;
  }
  Jet& operator*=(double s) {
    for (auto& v : c) v *= s;
    return *this;
  }
};

template <int N> Jet<N> operator+(Jet<N> a, const Jet<N>& b) { return a += b; }
template <int N> Jet<N> operator-(Jet<N> a, const Jet<N>& b) { return a -= b; }
template <int N> Jet<N> operator-(Jet<N> a) { return a *= -1.0; }
template <int N> Jet<N> operator*(Jet<N> a, double s) { return a *= s; }
template <int N> Jet<N> operator*(double s, Jet<N> a) { return a *= s; }
template <int N> Jet<N> operator+(Jet<N> a, double s) {
  a.c[0] += s;
  return a;
}
template <int N> Jet<N> operator+(double s, Jet<N> a) { return a + s; }

/// Cauchy product, truncated after h^N.
template <int N>
Jet<N> operator*(const Jet<N>& a, const Jet<N>& b) {
  Jet<N> r;
  for (int k = 0; k <= N; ++k) {
    double s = 0.0;
    for (int j = 0; j <= k; ++j) s += a.c[j] * b.c[k - j];
    r.c[k] = s;
  }
  return r;
}

/// a / b for b.c[0] != 0: solves b * q = a order by order.
template <int N>
Jet<N> operator/(const Jet<N>& a, const Jet<N>& b) {
  Jet<N> q;
  for (int k = 0; k <= N; ++k) {
    double s = a.c[k];
    for (int j = 1; j <= k; ++j) s -= b.c[j] * q.c[k - j];
    q.c[k] = s / b.c[0];
  }
  return q;
}

/// sqrt(a) for a.c[0] > 0: solves y * y = a order by order.
template <int N>
Jet<N> sqrt(const Jet<N>& a) {
  Jet<N> y;
  y.c[0] = std::sqrt(a.c[0]);
  for (int k = 1; k <= N; ++k) {
    double s = a.c[k];
    for (int j = 1; j < k; ++j) s -= y.c[j] * y.c[k - j];
    y.c[k] = s / (2.0 * y.c[0]);
  }
  return y;
}

/// The series of f'(t0 + h), one order shorter.
template <int N>
Jet<N - 1> derivative(const Jet<N>& a) {
  static_assert(N >= 1);
  Jet<N - 1> d;
  for (int k = 0; k < N; ++k) d.c[k] = (k + 1) * a.c[k + 1];
  return d;
}

/// Drops the orders above M.
template <int M, int N>
Jet<M> truncate(const Jet<N>& a) {
  static_assert(M <= N);
  Jet<M> r;
  for (int k = 0; k <= M; ++k) r.c[k] = a.c[k];
  return r;
}

}  // namespace bendlab
