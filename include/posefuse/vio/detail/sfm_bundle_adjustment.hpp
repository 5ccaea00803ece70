#pragma once
/// @file
/// The small bundle adjustment of vio/sfm.hpp: Levenberg–Marquardt over camera
/// poses and 3-D points with a robust loss, the points eliminated by the
/// Schur complement so that only a 6N × 6N system is factorised.
///
/// Residual of an observation m of point p in camera f: the reprojection
/// residual of vio/pnp.hpp, \f$ r = \phi\,(\pi(T_f^{-1} p) - m) \f$, in pixels
/// (φ the focal length), with its analytic Jacobians (checked in the PnP
/// tests); \f$ T_f \leftarrow T_f\,\mathrm{Exp}(\delta_f) \f$, \f$ p \leftarrow p + \delta_p \f$.
/// The loss \f$ \rho(|r|^2) \f$ (vio/robust_loss.hpp) enters as iteratively
/// re-weighted least squares. Observations whose point lies at depth
/// \f$ \le \f$ 1e-9 in the camera are left out of that iteration. The gauge is
/// fixed by the caller's list of held parameters (rows and columns of the
/// reduced system replaced by the identity).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>
#include <posefuse/lie/se3.hpp>
#include <posefuse/vio/pnp.hpp>
#include <posefuse/vio/robust_loss.hpp>

namespace posefuse::detail {

/// One observation of a bundle-adjustment point.
struct BaObservation {
  int frame;          ///< index into the poses
  Eigen::Vector2d m;  ///< normalised coordinates
};

/// Outcome of bundle_adjust.
struct BaSummary {
  double initial_cost = 0;  ///< robust cost before
  double final_cost = 0;    ///< robust cost after
  int iterations = 0;       ///< accepted steps
};

/// Robust cost \f$ \sum \rho(|r|^2) \f$ (pixels) over the observations in front of their camera.
inline double ba_cost(const std::vector<SE3d>& T, const std::vector<Eigen::Vector3d>& p,
                      const std::vector<std::vector<BaObservation>>& obs, double focal, const ReprojectionLoss& loss) {
  double c = 0;
  for (std::size_t j = 0; j < p.size(); ++j) {
    for (const BaObservation& o : obs[j]) {
      double z = 0;
      const Eigen::Vector2d r = focal * reprojection_residual(T[o.frame], p[j], o.m, nullptr, nullptr, &z);
      if (z > 1e-9) c += loss.rho(r.squaredNorm());
    }
  }
  return c;
}

/// Levenberg–Marquardt with the points eliminated (see the file comment).
/// @param[in,out] T camera poses T_w_c
/// @param[in,out] p points in w
/// @param[in] obs observations of each point
/// @param[in] held pose parameters held fixed (index 6 f + k, k in [ρ, φ])
inline BaSummary bundle_adjust(std::vector<SE3d>& T, std::vector<Eigen::Vector3d>& p,
                               const std::vector<std::vector<BaObservation>>& obs, const std::vector<int>& held,
                               double focal, const ReprojectionLoss& loss, int iterations) {
  using M63 = Eigen::Matrix<double, 6, 3>;
  const int nf = int(T.size());
  const int np = int(p.size());
  const std::size_t unp = p.size();
  const int dim = 6 * nf;
  BaSummary sum;
  double cost = ba_cost(T, p, obs, focal, loss);
  sum.initial_cost = cost;
  double lambda = 1e-4;
  std::vector<char> is_held(std::size_t(dim), 0);
  for (int h : held) is_held[std::size_t(h)] = 1;

  for (int it = 0; it < iterations; ++it) {
    // Linearise: U (pose blocks), V_j, W_fj and the gradients.
    Eigen::MatrixXd U = Eigen::MatrixXd::Zero(dim, dim);
    Eigen::VectorXd gc = Eigen::VectorXd::Zero(dim);
    std::vector<Eigen::Matrix3d> V(unp, Eigen::Matrix3d::Zero());
    std::vector<Eigen::Vector3d> gp(unp, Eigen::Vector3d::Zero());
    std::vector<std::vector<std::pair<int, M63>>> W(unp);
    for (int j = 0; j < np; ++j) {
      for (const BaObservation& o : obs[std::size_t(j)]) {
        Eigen::Matrix<double, 2, 6> Jc;
        Eigen::Matrix<double, 2, 3> Jp;
        double z = 0;
        const Eigen::Vector2d r = focal * reprojection_residual(T[o.frame], p[std::size_t(j)], o.m, &Jc, &Jp, &z);
        if (!(z > 1e-9)) continue;
        const double w = loss.d_rho(r.squaredNorm());
        Jc *= focal;
        Jp *= focal;
        U.block<6, 6>(6 * o.frame, 6 * o.frame).noalias() += w * Jc.transpose() * Jc;
        gc.segment<6>(6 * o.frame).noalias() += w * Jc.transpose() * r;
        V[std::size_t(j)].noalias() += w * Jp.transpose() * Jp;
        gp[std::size_t(j)].noalias() += w * Jp.transpose() * r;
        auto& Wj = W[std::size_t(j)];
        if (Wj.empty() || Wj.back().first != o.frame) Wj.emplace_back(o.frame, M63::Zero());
        Wj.back().second.noalias() += w * Jc.transpose() * Jp;
      }
    }
    if (gc.cwiseAbs().maxCoeff() < 1e-12 && std::all_of(gp.begin(), gp.end(), [](const Eigen::Vector3d& g) {
          return g.cwiseAbs().maxCoeff() < 1e-12;
        }))
      break;

    bool accepted = false;
    for (int attempt = 0; attempt < 10 && !accepted; ++attempt) {
      // Damped reduced system S dc = rhs.
      Eigen::MatrixXd S = U;
      S.diagonal() += lambda * (U.diagonal().array() + 1e-9).matrix();
      Eigen::VectorXd rhs = -gc;
      std::vector<Eigen::Matrix3d> Vinv(unp);
      for (int j = 0; j < np; ++j) {
        Eigen::Matrix3d Vd = V[std::size_t(j)];
        Vd.diagonal() += lambda * (V[std::size_t(j)].diagonal().array() + 1e-9).matrix();
        Vinv[std::size_t(j)] = Vd.inverse();
        const auto& Wj = W[std::size_t(j)];
        for (std::size_t a = 0; a < Wj.size(); ++a) {
          const int fa = Wj[a].first;
          const M63 WaVi = Wj[a].second * Vinv[std::size_t(j)];
          rhs.segment<6>(6 * fa).noalias() += WaVi * gp[std::size_t(j)];
          for (std::size_t b = a; b < Wj.size(); ++b)  // upper blocks; mirrored below
            S.block<6, 6>(6 * std::min(fa, Wj[b].first), 6 * std::max(fa, Wj[b].first)).noalias() -=
                fa <= Wj[b].first ? Eigen::Matrix<double, 6, 6>(WaVi * Wj[b].second.transpose())
                                  : Eigen::Matrix<double, 6, 6>(Wj[b].second * WaVi.transpose());
        }
      }
      S.triangularView<Eigen::StrictlyLower>() = S.transpose();
      for (int h = 0; h < dim; ++h) {
        if (!is_held[std::size_t(h)]) continue;
        S.row(h).setZero();
        S.col(h).setZero();
        S(h, h) = 1.0;
        rhs(h) = 0.0;
      }
      const Eigen::VectorXd dc = S.ldlt().solve(rhs);
      if (!dc.allFinite()) {
        lambda *= 10.0;
        continue;
      }
      std::vector<SE3d> Tn = T;
      for (int f = 0; f < nf; ++f) Tn[std::size_t(f)] = T[std::size_t(f)].plus(dc.segment<6>(6 * f));
      std::vector<Eigen::Vector3d> pn = p;
      for (int j = 0; j < np; ++j) {
        Eigen::Vector3d b = -gp[std::size_t(j)];
        for (const auto& [f, Wf] : W[std::size_t(j)]) b.noalias() -= Wf.transpose() * dc.segment<6>(6 * f);
        pn[std::size_t(j)] += Vinv[std::size_t(j)] * b;
      }
      const double cn = ba_cost(Tn, pn, obs, focal, loss);
      if (std::isfinite(cn) && cn <= cost) {
        accepted = true;
        const bool converged = cost - cn <= 1e-12 * cost;
        T = std::move(Tn);
        p = std::move(pn);
        cost = cn;
        ++sum.iterations;
        lambda = std::max(lambda * 0.1, 1e-10);
        if (converged) it = iterations;
      } else {
        lambda *= 10.0;
      }
    }
    if (!accepted) break;
  }
  sum.final_cost = cost;
  return sum;
}

}  // namespace posefuse::detail
