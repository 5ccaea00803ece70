#pragma once
/// @file
/// The measurement update of posefuse::BasicEkf (filters/ekf.hpp), in two
/// halves that every update takes:
///
/// 1. compute_gain(): the half that depends on the prior covariance P alone
///    (not on the measurement): \f$ S = H P H^\top + R \f$, its
///    positive-definiteness test and solver (core/spd_solver.hpp),
///    \f$ K = P H^\top S^{-1} \f$ and the posterior covariance, kept in an
///    EkfGain. How it is computed depends on H's structure, known at compile
///    time: a row selection with one to three rows
///    (closed_form_selection_gain), a larger row selection, or a dense
///    Jacobian (dense_gain).
/// 2. apply_gain(): the one tail: the innovation \f$ r = z \boxminus h(\bar
///    x) \f$, the NIS \f$ r^\top S^{-1} r \f$, the gates, and \f$ x \boxplus
///    K r \f$ with the posterior covariance, stored only if all of it passed.
///
/// The filter may keep an EkfGain across updates (EkfGainMemo, the
/// steady-state memo) and apply it again while P repeats; the result is the
/// same, bit for bit, as computing it afresh.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <limits>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/definiteness.hpp>
#include <posefuse/core/spd_solver.hpp>
#include <posefuse/core/status.hpp>
#include <posefuse/filters/ekf_options.hpp>
#include <posefuse/filters/ekf_update_result.hpp>
#include <type_traits>

namespace posefuse::detail {

// ---------------------------------------------------------------------------
// The structure of a measurement model's Jacobian

/// True when H's Jacobian selects state components (each row a unit row):
/// H = I (kIdentityJacobian with Measurement::Dim == Dim) or its declared
/// `kSelection` (has_selection_v). The update then reads rows and columns of
/// P instead of multiplying by H.
template <class H, int Dim>
inline constexpr bool is_row_selection_v =
    (has_identity_jacobian_v<H> && DimOf<typename H::Measurement> == Dim) || has_selection_v<H>;

/// A row selection with one to three rows (a position fix, a planar pose
/// fix): S is inverted in closed form and the gain half runs on scalars
/// (closed_form_selection_gain).
template <class H, int Dim>
inline constexpr bool is_closed_form_selection_v =
    is_row_selection_v<H, Dim> && DimOf<typename H::Measurement> <= 3;

/// The state components a row selection H picks, in measurement order: its
/// `kSelection`, or 0, 1, ... for H = I.
template <class H>
constexpr std::array<int, std::size_t(DimOf<typename H::Measurement>)> selected_components() {
  if constexpr (has_selection_v<H>) {
    return H::kSelection;
  } else {
    std::array<int, std::size_t(DimOf<typename H::Measurement>)> s{};
    for (std::size_t i = 0; i < s.size(); ++i) s[i] = int(i);
    return s;
  }
}

// ---------------------------------------------------------------------------
// Small helpers shared by the prediction and the update

/// True when every entry is finite, in one branch-free pass: v - v is 0 for
/// a finite entry and NaN for NaN or Inf.
template <class T, int N>
[[nodiscard, gnu::always_inline]] inline bool all_entries_finite(const Eigen::Matrix<T, N, 1>& v) noexcept {
  T s = T(0);
  for (int i = 0; i < N; ++i) s += v(i) - v(i);
  return s == T(0);
}

/// Copies the lower triangle onto the upper one (exactly symmetric; no arithmetic).
template <class Cov>
[[gnu::always_inline]] inline void mirror_lower(Cov& P) noexcept {
  for (int j = 0; j < Cov::RowsAtCompileTime; ++j)
    for (int i = j + 1; i < Cov::RowsAtCompileTime; ++i) P(j, i) = P(i, j);
}

/// Every entry equal (==) to the other's.
template <class Cov>
[[nodiscard, gnu::always_inline]] inline bool same_values(const Cov& a, const Cov& b) noexcept {
  for (int i = 0; i < Cov::SizeAtCompileTime; ++i)
    if (a.data()[i] != b.data()[i]) return false;
  return true;
}

/// `r` with its status set to `s`.
template <class R>
[[nodiscard]] R with_status(R r, FilterStatus s) {
  r.status = s;
  return r;
}

/// psd_reference(P, false), kept out of line. Not marked cold: with that
/// attribute g++ 12 also took the accepted path after an inlined update for
/// never executed and moved it to the cold section (slower bench_filters
/// steps).
template <class Cov>
[[gnu::noinline]] bool psd_reference_out_of_line(const Cov& P) {
  return psd_reference(P, false);
}
/// is_positive_semidefinite() for a result of the filter, with its fast path
/// inlined for small sizes and the reference out of line (same decisions).
template <class Cov>
[[nodiscard, gnu::always_inline]] inline bool psd_accepts(const Cov& P) {
  if constexpr (Cov::RowsAtCompileTime <= 4) {
    if (psd_fast_accepts(P)) [[likely]]
      return true;
    return psd_reference_out_of_line(P);
  } else {
    return is_positive_semidefinite(P);
  }
}

/// The status of a covariance refused by psd_accepts(): kNonFinite when it
/// has NaN or Inf (which psd_accepts() also refuses), else kNotPositiveDefinite.
template <class Cov>
[[nodiscard]] FilterStatus refused_covariance_status(const Cov& P) {
  return P.allFinite() ? FilterStatus::kNotPositiveDefinite : FilterStatus::kNonFinite;
}

/// The status of a posterior covariance: kApplied when psd_accepts() it.
/// Joseph's form is PSD in exact arithmetic; with a singular or badly
/// scaled prior, rounding can still give a negative variance. Such a result
/// is refused (core/definiteness.hpp's criterion, which also refuses NaN and
/// Inf), never stored.
template <class Cov>
[[nodiscard, gnu::always_inline]] inline FilterStatus posterior_status(const Cov& P) {
  if (!psd_accepts(P)) return refused_covariance_status(P);
  return FilterStatus::kApplied;
}

// ---------------------------------------------------------------------------
// The gain half

/// The half of an update with measurement model H that depends on P alone:
/// S, its solver, K and the posterior covariance. A default-constructed
/// gain is not initialised (compute_gain() fills it); zero() is.
template <class H>
struct EkfGain {
  using Scalar = ScalarOf<typename H::State>;
  static constexpr int Dim = DimOf<typename H::State>;
  static constexpr int M = DimOf<typename H::Measurement>;
  using SMat = CovarianceOf<typename H::Measurement>;
  using Covariance = CovarianceOf<typename H::State>;
  using GainMatrix = Eigen::Matrix<Scalar, Dim, M>;

  SMat S;
  SpdSolver<SMat> solver;
  GainMatrix K;
  Covariance P_post;

  /// A gain with every entry zero (as a kept gain starts).
  static EkfGain zero() {
    EkfGain g;
    g.S.setZero();
    g.K.setZero();
    g.P_post.setZero();
    return g;
  }
};

/// The steady-state memo of one measurement model. A gain is kept only for
/// a prior P seen three times in a row: an update whose P is new records
/// its first and last variances; when the next prior repeats both, it is
/// recorded whole (P_in); the next update with exactly P_in computes the
/// gain into the memo; later ones with that P reuse it. So a filter whose
/// P keeps changing pays two comparisons and two stores per update, not a
/// copy of P.
template <class H>
struct EkfGainMemo {
  using Covariance = CovarianceOf<typename H::State>;
  using Scalar = ScalarOf<typename H::State>;
  bool valid = false;     ///< gain holds the update for P_in
  bool recorded = false;  ///< P_in holds the last prior
  Scalar first = std::numeric_limits<Scalar>::quiet_NaN();  ///< the last prior's P(0, 0)
  Scalar last = std::numeric_limits<Scalar>::quiet_NaN();   ///< the last prior's P(Dim-1, Dim-1)
  Covariance P_in = Covariance::Constant(std::numeric_limits<ScalarOf<typename H::State>>::quiet_NaN());
  EkfGain<H> gain = EkfGain<H>::zero();
};

/// compute_gain() for a row selection H with one to three rows, on scalars
/// (kept in registers): S, its closed-form test and inverse (SpdSolver),
/// then \f$ U = P H^\top \mathrm{adj}(S) \f$ and \f$ W = U S U^\top \f$,
/// which do not wait for \f$ g = 1 / \det S \f$, so that the division is
/// the only step between S and the posterior. \f$ K = g U \f$ (= P Hᵀ
/// S⁻¹), and Joseph's form expanded for a symmetric P, \f$ (I - K H) P (I -
/// K H)^\top + K R K^\top = P - K H P - P H^\top K^\top + K S K^\top \f$
/// (each term a function of the computed K, so an error in K still enters
/// only to second order), one triangle: \f$ P^+_{ij} = P_{ij} - g\,(U_i
/// \cdot B_j + B_i \cdot U_j) + g^2 W_{ij} \f$, B = P Hᵀ. kStandard:
/// \f$ P_{ij} - g\, U_i \cdot B_j \f$.
template <class Options, class H>
[[gnu::always_inline]] inline FilterStatus closed_form_selection_gain(
    const H& sensor, const typename H::State& x, const CovarianceOf<typename H::State>& P,
    EkfGain<H>& g) {
  using Scalar = typename EkfGain<H>::Scalar;
  constexpr int Dim = EkfGain<H>::Dim;
  constexpr int M = EkfGain<H>::M;
  static_assert(M >= 1 && M <= 3);
  constexpr std::array<int, std::size_t(M)> sel = selected_components<H>();
  const auto R = measurement_noise(sensor, x);
  Scalar B[Dim][M];  // P H^T: the selected columns of P
  for (int i = 0; i < Dim; ++i)
    for (int a = 0; a < M; ++a) B[i][a] = P(i, sel[std::size_t(a)]);
  Scalar S[M][M];
  for (int a = 0; a < M; ++a)
    for (int b = 0; b < M; ++b) {
      S[a][b] = B[sel[std::size_t(a)]][b] + R(a, b);
      g.S(a, b) = S[a][b];
    }
  if (!g.solver.compute(g.S)) return FilterStatus::kNotPositiveDefinite;
  Scalar U[Dim][M];  // P H^T adj(S)
  for (int i = 0; i < Dim; ++i) {
    if constexpr (M == 1) {
      U[i][0] = B[i][0];
    } else if constexpr (M == 2) {
      U[i][0] = B[i][0] * S[1][1] - B[i][1] * S[1][0];
      U[i][1] = B[i][1] * S[0][0] - B[i][0] * S[0][1];
    } else {
      const auto& A = g.solver.adjugate();
      for (int a = 0; a < 3; ++a) U[i][a] = B[i][0] * A(0, a) + B[i][1] * A(1, a) + B[i][2] * A(2, a);
    }
  }
  const Scalar rd = g.solver.recip_det();
  for (int i = 0; i < Dim; ++i)
    for (int a = 0; a < M; ++a) g.K(i, a) = rd * U[i][a];
  auto& P_post = g.P_post;
  if constexpr (Options::kCovarianceUpdate == CovarianceUpdate::kStandard) {
    for (int j = 0; j < Dim; ++j)
      for (int i = j; i < Dim; ++i) {
        Scalar c = U[i][0] * B[j][0];
        for (int a = 1; a < M; ++a) c += U[i][a] * B[j][a];
        const Scalar v = P(i, j) - rd * c;
        P_post(i, j) = v;
        P_post(j, i) = v;
      }
  } else {
    Scalar V[Dim][M];  // U S
    for (int i = 0; i < Dim; ++i)
      for (int b = 0; b < M; ++b) {
        Scalar v = U[i][0] * S[0][b];
        for (int a = 1; a < M; ++a) v += U[i][a] * S[a][b];
        V[i][b] = v;
      }
    const Scalar rd2 = rd * rd;
    for (int j = 0; j < Dim; ++j)
      for (int i = j; i < Dim; ++i) {
        Scalar c = U[i][0] * B[j][0] + B[i][0] * U[j][0];
        Scalar w = V[i][0] * U[j][0];
        for (int a = 1; a < M; ++a) {
          c += U[i][a] * B[j][a] + B[i][a] * U[j][a];
          w += V[i][a] * U[j][a];
        }
        const Scalar v = (P(i, j) - rd * c) + rd2 * w;
        P_post(i, j) = v;
        P_post(j, i) = v;
      }
  }
  return posterior_status(P_post);
}

/// compute_gain() for a dense H, or a row selection with three or more
/// rows: S factorised by SpdSolver, \f$ K = P H^\top S^{-1} \f$ by solving,
/// \f$ A = (I - K H) P \f$, and for Joseph's form \f$ A (I - K H)^\top + K
/// R K^\top = A + (K R - A H^\top) K^\top \f$; one triangle, mirrored. A
/// selection reads rows and columns of P and A instead of multiplying by H.
template <class Options, class H>
[[gnu::always_inline]] inline FilterStatus dense_gain(const H& sensor, const typename H::State& x,
                                                      const CovarianceOf<typename H::State>& P,
                                                      EkfGain<H>& g) {
  using Scalar = typename EkfGain<H>::Scalar;
  using Covariance = typename EkfGain<H>::Covariance;
  constexpr int Dim = EkfGain<H>::Dim;
  constexpr int M = EkfGain<H>::M;
  constexpr bool kSelects = is_row_selection_v<H, Dim>;
  using HP = Eigen::Matrix<Scalar, M, Dim>;
  using Nm = Eigen::Matrix<Scalar, Dim, M>;
  const typename EkfGain<H>::SMat R = measurement_noise(sensor, x);
  HP JP;  // H P, which is (P H^T)^T for the symmetric P
  [[maybe_unused]] MeasurementJacobianOf<H> J;
  if constexpr (kSelects) {
    constexpr std::array<int, std::size_t(M)> sel = selected_components<H>();
    for (int a = 0; a < M; ++a) {
      JP.row(a) = P.row(sel[std::size_t(a)]);
      for (int b = 0; b < M; ++b) g.S(a, b) = P(sel[std::size_t(a)], sel[std::size_t(b)]) + R(a, b);
    }
  } else {
    J = sensor.jacobian(x);
    JP = J * P;
    g.S = JP * J.transpose() + R;
  }
  if (!g.solver.compute(g.S)) return FilterStatus::kNotPositiveDefinite;
  g.K = g.solver.right_solve(Nm(JP.transpose()));  // P H^T S^-1
  const Covariance A = P - g.K.lazyProduct(JP);    // (I - K H) P
  if constexpr (Options::kCovarianceUpdate == CovarianceUpdate::kStandard) {
    g.P_post = A;
    mirror_lower(g.P_post);
  } else {
    Nm AHt;
    if constexpr (kSelects) {
      constexpr std::array<int, std::size_t(M)> sel = selected_components<H>();
      for (int a = 0; a < M; ++a) AHt.col(a) = A.col(sel[std::size_t(a)]);
    } else {
      AHt = A * J.transpose();
    }
    const Nm C = g.K.lazyProduct(R) - AHt;
    for (int j = 0; j < Dim; ++j) {
      for (int i = j; i < Dim; ++i) {
        Scalar v = A(i, j);
        for (int k = 0; k < M; ++k) v += C(i, k) * g.K(j, k);
        g.P_post(i, j) = v;
        g.P_post(j, i) = v;
      }
    }
  }
  return posterior_status(g.P_post);
}

/// The gain half of an update with `sensor` at the prior (x, P), into g.
/// @return kApplied, kNotPositiveDefinite (S, or the posterior covariance,
///         is not positive (semi-)definite) or kNonFinite (the posterior
///         covariance has NaN or Inf); g is usable only after kApplied
template <class Options, class H>
[[nodiscard, gnu::always_inline]] inline FilterStatus compute_gain(
    const H& sensor, const typename H::State& x, const CovarianceOf<typename H::State>& P,
    EkfGain<H>& g) {
  if constexpr (is_closed_form_selection_v<H, EkfGain<H>::Dim>) {
    return closed_form_selection_gain<Options>(sensor, x, P, g);
  } else {
    return dense_gain<Options>(sensor, x, P, g);
  }
}

// ---------------------------------------------------------------------------
// The apply tail

/// The gate of an update without a gate functor.
struct NoGate {};

/// Whether an update computes its NIS (Options::kNis).
template <class Options, class H, class Gate>
[[nodiscard]] bool needs_nis(ScalarOf<typename H::State> nis_gate) noexcept {
  using Scalar = ScalarOf<typename H::State>;
  if constexpr (Options::kNis == NisPolicy::kAlways) {
    return true;
  } else {
    using Innov = typename UpdateResult<H>::Innovation;
    using InnovCov = typename UpdateResult<H>::InnovationCovariance;
    if constexpr (std::is_arithmetic_v<Gate> ||
                  std::is_invocable_r_v<bool, const Gate&, const Innov&, const InnovCov&, Scalar>) {
      return true;
    } else {
      return nis_gate < std::numeric_limits<Scalar>::infinity();
    }
  }
}

/// True when `gate` (NoGate, a NIS threshold or a functor) accepts r.
template <class H, class Gate>
[[nodiscard]] bool gate_accepts(const Gate& gate, const UpdateResult<H>& r) {
  using Scalar = ScalarOf<typename H::State>;
  using Innov = typename UpdateResult<H>::Innovation;
  using InnovCov = typename UpdateResult<H>::InnovationCovariance;
  if constexpr (std::is_same_v<Gate, NoGate>) {
    return true;
  } else if constexpr (std::is_arithmetic_v<Gate>) {
    return r.nis <= static_cast<Scalar>(gate);
  } else if constexpr (std::is_invocable_r_v<bool, const Gate&, const Innov&, const InnovCov&, Scalar>) {
    return static_cast<bool>(gate(r.innovation, r.S, r.nis));
  } else {
    return static_cast<bool>(gate(r.innovation, r.S));
  }
}

/// The tail of every update: the innovation of z at x, its NIS (when
/// Options::kNis asks for it) against `nis_gate`, then `gate`; if all
/// pass and the new state is finite, \f$ x \leftarrow x \boxplus K r \f$
/// and \f$ P \leftarrow \f$ g.P_post. Otherwise x and P are unchanged.
/// @return the status and the innovation statistics
template <class Options, class H, class Gate>
[[nodiscard, gnu::always_inline, gnu::flatten]] inline UpdateResult<H> apply_gain(
    const H& sensor, const typename H::Measurement& z, ScalarOf<typename H::State> nis_gate,
    const Gate& gate, const EkfGain<H>& g, typename H::State& x,
    CovarianceOf<typename H::State>& P) {
  using StateType = typename H::State;
  using Z = typename H::Measurement;
  UpdateResult<H> out;  // status kNonFinite; every path returns this object
  out.S = g.S;
  out.innovation = posefuse::minus(z, static_cast<Z>(sensor.predict(x)));
  if (!all_entries_finite(out.innovation)) return out;
  out.status = FilterStatus::kGated;
  if (needs_nis<Options, H, Gate>(nis_gate)) {
    out.nis = g.solver.nis(out.innovation);
    if (!(out.nis <= nis_gate)) return out;
  }
  if (!gate_accepts<H>(gate, out)) return out;
  out.status = FilterStatus::kNonFinite;
  TangentOf<StateType> dx;  // K r
  if constexpr (EkfGain<H>::M <= 3) {
    // Row by row on scalars (the sums Eigen's product forms for up to three
    // columns): closed_form_selection_gain() writes K entry by entry, and
    // reading it back in pairs stalls store-to-load forwarding.
    for (int i = 0; i < EkfGain<H>::Dim; ++i) {
      ScalarOf<StateType> v = g.K(i, 0) * out.innovation(0);
      if constexpr (EkfGain<H>::M >= 2) v += g.K(i, 1) * out.innovation(1);
      if constexpr (EkfGain<H>::M == 3) v += g.K(i, 2) * out.innovation(2);
      dx(i) = v;
    }
  } else {
    dx = g.K * out.innovation;
  }
  const StateType x_new = posefuse::plus(x, dx);
  if (!all_entries_finite(posefuse::minus(x_new, x))) return out;
  x = x_new;
  P = g.P_post;
  out.status = FilterStatus::kApplied;
  return out;
}

/// A whole update with `sensor`, its gain computed afresh.
template <class Options, class H, class Gate>
[[nodiscard, gnu::always_inline]] inline UpdateResult<H> update_afresh(
    const H& sensor, const typename H::Measurement& z, ScalarOf<typename H::State> nis_gate,
    const Gate& gate, typename H::State& x, CovarianceOf<typename H::State>& P) {
  EkfGain<H> g;
  const FilterStatus s = compute_gain<Options>(sensor, x, P, g);
  if (s != FilterStatus::kApplied) return with_status(UpdateResult<H>{}, s);
  return apply_gain<Options>(sensor, z, nis_gate, gate, g, x, P);
}

}  // namespace posefuse::detail
