"""posefuse.ekf_* and rts_smooth against a Kalman filter and RTS smoother
written here in numpy (Thrun et al. Table 3.3 with Joseph's covariance form;
the heading of planar poses wrapped in the residual and the correction;
Rauch-Tung-Striebel as Sarkka 2013 Thm 8.2), with each model's prediction,
Jacobian and noise from its header's formulas."""
import math

import numpy as np
import pytest

import posefuse as pf

RNG = np.random.default_rng(11)


def wrap(a):
    return (np.asarray(a) + math.pi) % (2 * math.pi) - math.pi


class NumpyEkf:
    def __init__(self, f, angle_index=None):
        self.f = f  # (x, u, dt) -> (x', F, Q)
        self.ai = angle_index

    def boxminus(self, a, b):
        d = np.array(a, float) - b
        if self.ai is not None:
            d[self.ai] = wrap(d[self.ai])
        return d

    def boxplus(self, x, d):
        y = np.array(x, float) + d
        if self.ai is not None:
            y[self.ai] = wrap(y[self.ai])
        return y

    def run(self, x0, P0, controls, dts, fixes, H, Rz, mask, gate=math.inf):
        x, P = np.array(x0, float), np.array(P0, float)
        out = {k: [] for k in ("x", "P", "xp", "Pp", "F", "nis", "status")}
        for k in range(len(fixes)):
            x, F, Q = self.f(x, controls[k], dts[k])
            P = F @ P @ F.T + Q
            out["xp"].append(x.copy()), out["Pp"].append(P.copy()), out["F"].append(F)
            nis, st = math.nan, "no measurement"
            if mask[k]:
                zh = H @ x
                r = np.array(fixes[k], float) - zh
                if self.ai is not None and H.shape[0] == 3:
                    r[2] = wrap(r[2])
                S = H @ P @ H.T + Rz
                nis = r @ np.linalg.solve(S, r)
                if nis > gate:
                    st = "rejected by gate"
                else:
                    K = P @ H.T @ np.linalg.inv(S)
                    x = self.boxplus(x, K @ r)
                    A = np.eye(len(x)) - K @ H
                    P = A @ P @ A.T + K @ Rz @ K.T
                    st = "applied"
            out["x"].append(x.copy()), out["P"].append(P.copy())
            out["nis"].append(nis), out["status"].append(st)
        return {k: (np.array(v) if k != "status" else v) for k, v in out.items()}

    def rts(self, run):
        xs, Ps = run["x"].copy(), run["P"].copy()
        for k in range(len(xs) - 2, -1, -1):
            C = run["P"][k] @ run["F"][k + 1].T @ np.linalg.inv(run["Pp"][k + 1])
            xs[k] = self.boxplus(run["x"][k], C @ self.boxminus(xs[k + 1], run["xp"][k + 1]))
            Pk = run["P"][k] + C @ (Ps[k + 1] - run["Pp"][k + 1]) @ C.T
            Ps[k] = 0.5 * (Pk + Pk.T)
        return xs, Ps


def check(run, ref, rtol=1e-9):
    scale_x = np.abs(ref["x"]).max() + 1
    np.testing.assert_allclose(run.states, ref["x"], rtol=0, atol=rtol * scale_x)
    np.testing.assert_allclose(run.covariances, ref["P"], rtol=rtol, atol=rtol * np.abs(ref["P"]).max())
    np.testing.assert_allclose(run.predicted_states, ref["xp"], rtol=0, atol=rtol * scale_x)
    np.testing.assert_allclose(run.predicted_covariances, ref["Pp"], rtol=rtol, atol=rtol * np.abs(ref["Pp"]).max())
    np.testing.assert_allclose(run.jacobians, ref["F"], rtol=0, atol=1e-12 * scale_x)
    np.testing.assert_allclose(run.nis, ref["nis"], rtol=1e-7, atol=1e-12)
    assert run.status == ref["status"]


# ---- seed 000 ------------------------------------------------------------------

def test_seed000_equals_the_linear_kalman_filter_and_rts():
    n = 60
    truth = np.cumsum(RNG.normal([1.0, 0.2], 0.1, (n, 2)), axis=0)
    u = np.diff(np.r_[[[0.0, 0.0]], truth], axis=0) + RNG.normal(0, 0.05, (n, 2))
    z = truth + RNG.normal(0, 0.3, (n, 2))
    R = np.array([[0.01, 0.002], [0.002, 0.02]])
    Q = np.diag([0.09, 0.09])
    mask = np.arange(n) % 3 != 1
    run = pf.ekf_seed000([0.0, 0.0], np.eye(2) * 0.1, u, z, R, Q, mask=mask)
    assert run.model == "seed000" and len(run) == n
    ref = NumpyEkf(lambda x, c, dt: (x + c, np.eye(2), R)).run([0, 0], np.eye(2) * 0.1, u, [0] * n, z, np.eye(2), Q, mask)
    check(run, ref)
    assert np.isnan(run.innovations[1]).all() and not np.isnan(run.innovations[0]).any()
    xs, Ps = pf.rts_smooth(run)
    xr, Pr = NumpyEkf(None).rts(ref)
    np.testing.assert_allclose(xs, xr, rtol=0, atol=1e-9 * np.abs(xr).max())
    np.testing.assert_allclose(Ps, Pr, rtol=1e-8, atol=1e-12)
    # smoothing helps: errors to the truth shrink on average
    assert np.mean(np.linalg.norm(xs - truth, axis=1)) < np.mean(np.linalg.norm(run.states - truth, axis=1))


def test_gate_rejects_an_outlier_and_keeps_the_prediction():
    n = 10
    u = np.tile([1.0, 0.0], (n, 1))
    z = np.cumsum(u, axis=0)
    z[5] += [50.0, 0.0]
    run = pf.ekf_seed000([0, 0], np.eye(2), u, z, np.eye(2) * 0.01, np.eye(2) * 0.01, gate=9.21)
    assert run.status[5] == "rejected by gate" and run.status[4] == "applied"
    np.testing.assert_array_equal(run.states[5], run.predicted_states[5])
    assert run.nis[5] > 9.21


# ---- constant velocity ------------------------------------------------------------

def cv_model(q):
    def f(x, c, dt):
        F = np.eye(4)
        F[0, 2] = F[1, 3] = dt
        Q = q * np.block([[dt ** 3 / 3 * np.eye(2), dt ** 2 / 2 * np.eye(2)], [dt ** 2 / 2 * np.eye(2), dt * np.eye(2)]])
        return F @ x, F, Q
    return f


def test_constant_velocity_equals_the_kalman_filter():
    n = 40
    dt = 0.1 + 0.05 * RNG.random(n)
    t = np.cumsum(dt)
    z = np.c_[3 * t + np.sin(t), -t] + RNG.normal(0, 0.2, (n, 2))
    R = np.eye(2) * 0.04
    run = pf.ekf_constant_velocity([0, 0, 1, 0], np.eye(4), dt, z, 0.5, R)
    ref = NumpyEkf(cv_model(0.5)).run([0, 0, 1, 0], np.eye(4), [None] * n, dt, z, np.eye(2, 4), R, [True] * n)
    check(run, ref)
    run1 = pf.ekf_constant_velocity([0, 0, 1, 0], np.eye(4), 0.1, z, 0.5, R)  # one dt for every step
    ref1 = NumpyEkf(cv_model(0.5)).run([0, 0, 1, 0], np.eye(4), [None] * n, [0.1] * n, z, np.eye(2, 4), R, [True] * n)
    check(run1, ref1)
    xs, Ps = pf.rts_smooth(run)
    xr, Pr = NumpyEkf(None).rts(ref)
    np.testing.assert_allclose(xs, xr, rtol=0, atol=1e-8 * np.abs(xr).max())
    np.testing.assert_allclose(Ps, Pr, rtol=1e-7, atol=1e-12)


# ---- unicycle and SE(2) odometry (planar poses, wrapped heading) ------------------------

def unicycle_model(cov, euler=False):
    def f(x, c, dt):
        ds, dth = c[0] * dt, c[1] * dt
        th = x[2]
        if euler:
            xn = np.array([x[0] + ds * math.cos(th), x[1] + ds * math.sin(th), wrap(th + dth)])
            F = np.array([[1, 0, -ds * math.sin(th)], [0, 1, ds * math.cos(th)], [0, 0, 1.0]])
            Ju = np.array([[math.cos(th), 0], [math.sin(th), 0], [0, 1.0]])
        else:
            h = dth / 2
            s = math.sin(h) / h if h != 0 else 1.0
            ds_ = (h * math.cos(h) - math.sin(h)) / h ** 2 if h != 0 else 0.0
            c_, sn = math.cos(th + h), math.sin(th + h)
            xn = np.array([x[0] + ds * s * c_, x[1] + ds * s * sn, wrap(th + dth)])
            F = np.array([[1, 0, -ds * s * sn], [0, 1, ds * s * c_], [0, 0, 1.0]])
            Ju = np.array([[s * c_, ds * (0.5 * ds_ * c_ - 0.5 * s * sn)],
                           [s * sn, ds * (0.5 * ds_ * sn + 0.5 * s * c_)], [0, 1.0]])
        Q = dt * dt * Ju @ cov @ Ju.T
        return xn, F, 0.5 * (Q + Q.T)
    return f


@pytest.mark.parametrize("integration", ["exact_arc", "euler"])
def test_unicycle_equals_the_numpy_ekf(integration):
    n = 50
    u = np.c_[1.0 + 0.2 * RNG.random(n), 0.8 * np.sin(np.arange(n) / 5.0)]
    dt = 0.2
    x = np.zeros(3)
    truth = []
    for k in range(n):
        x, _, _ = unicycle_model(np.zeros((2, 2)), integration == "euler")(x, u[k], dt)
        truth.append(x)
    z = np.array(truth) + RNG.normal(0, [0.1, 0.1, 0.05], (n, 3))
    z[:, 2] = wrap(z[:, 2])
    cov = np.diag([0.01, 0.004])
    R = np.diag([0.01, 0.01, 0.0025])
    mask = np.arange(n) % 4 == 0
    run = pf.ekf_unicycle([0, 0, 0], np.eye(3) * 0.01, u, dt, z, cov, R, integration=integration, mask=mask)
    ref = NumpyEkf(unicycle_model(cov, integration == "euler"), angle_index=2).run(
        [0, 0, 0], np.eye(3) * 0.01, u, [dt] * n, z, np.eye(3), R, mask)
    check(run, ref)
    xs, Ps = pf.rts_smooth(run)
    xr, Pr = NumpyEkf(None, angle_index=2).rts(ref)
    np.testing.assert_allclose(xs, xr, rtol=0, atol=1e-8)
    np.testing.assert_allclose(Ps, Pr, rtol=1e-7, atol=1e-12)


def se2_model(kxy, kts, ktt):
    def f(x, c, dt):
        th = x[2]
        Rm = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
        t = Rm @ c[:2]
        dth = wrap(c[2])
        xn = np.array([x[0] + t[0], x[1] + t[1], wrap(th + dth)])
        F = np.array([[1, 0, -t[1]], [0, 1, t[0]], [0, 0, 1.0]])
        s = math.hypot(c[0], c[1])
        Q = np.diag([kxy ** 2 * s, kxy ** 2 * s, kts ** 2 * s + ktt ** 2 * abs(dth)])
        return xn, F, Q
    return f


def test_se2_odometry_equals_the_numpy_ekf_across_the_heading_wrap():
    n = 40
    inc = np.c_[np.full(n, 0.5), np.zeros(n), np.full(n, 0.3)]  # circles: the heading crosses +-pi
    z = np.zeros((n, 3))
    x = np.array([0.0, 0.0, 3.0])
    for k in range(n):
        x, _, _ = se2_model(0, 0, 0)(x, inc[k], 0)
        z[k] = x + RNG.normal(0, [0.05, 0.05, 0.02])
    z[:, 2] = wrap(z[:, 2])
    R = np.diag([0.0025, 0.0025, 0.0004])
    run = pf.ekf_se2_odometry([0, 0, 3.0], np.eye(3) * 0.001, inc, z, R)
    ref = NumpyEkf(se2_model(0.02, 0.005, 0.03), angle_index=2).run(
        [0, 0, 3.0], np.eye(3) * 0.001, inc, [0] * n, z, np.eye(3), R, [True] * n)
    check(run, ref)
    assert np.all(np.abs(run.states[:, 2]) <= math.pi)
    xs, _ = pf.rts_smooth(run)
    xr, _ = NumpyEkf(None, angle_index=2).rts(ref)
    np.testing.assert_allclose(xs, xr, rtol=0, atol=1e-8)


# ---- misuse -------------------------------------------------------------------------

def test_bad_input_raises_with_the_cpp_messages():
    u = np.ones((5, 2))
    z = np.ones((5, 2))
    I2 = np.eye(2)
    with pytest.raises(ValueError, match="Ekf::reset: covariance is not symmetric"):
        pf.ekf_seed000([0, 0], [[1, 0.5], [0, 1]], u, z, I2, I2)
    with pytest.raises(ValueError, match="Ekf::reset: state has NaN or Inf"):
        pf.ekf_seed000([np.nan, 0], I2, u, z, I2, I2)
    with pytest.raises(ValueError, match="PositionFix: measurement noise Q must be symmetric positive definite"):
        pf.ekf_seed000([0, 0], I2, u, z, I2, np.zeros((2, 2)))
    with pytest.raises(ValueError, match="PlanarDisplacement: process noise R"):
        pf.ekf_seed000([0, 0], I2, u, z, -I2, I2)
    with pytest.raises(ValueError, match="ConstantVelocity2: acceleration noise q must be finite and > 0"):
        pf.ekf_constant_velocity([0, 0, 0, 0], np.eye(4), 0.1, z, -1.0, I2)
    with pytest.raises(ValueError, match="Ekf::set_gate: threshold must be > 0"):
        pf.ekf_seed000([0, 0], I2, u, z, I2, I2, gate=-1.0)
    bad = z.copy()
    bad[3, 0] = np.nan
    with pytest.raises(ValueError, match="ekf_seed000: step 3: update: non-finite"):
        pf.ekf_seed000([0, 0], I2, u, bad, I2, I2)
    pf.ekf_seed000([0, 0], I2, u, bad, I2, I2, mask=[True, True, True, False, True])  # masked: fine
    badu = u.copy()
    badu[2, 1] = np.inf
    with pytest.raises(ValueError, match="ekf_seed000: step 2: prediction: non-finite"):
        pf.ekf_seed000([0, 0], I2, badu, z, I2, I2)
    with pytest.raises(ValueError, match=r"fixes: expected an array of shape \(5, 2\), got \(4, 2\)"):
        pf.ekf_seed000([0, 0], I2, u, z[:4], I2, I2)
    with pytest.raises(ValueError, match=r"x0: expected an array of shape \(2,\), got \(3,\)"):
        pf.ekf_seed000([0, 0, 0], I2, u, z, I2, I2)
    with pytest.raises(ValueError, match="mask: expected a bool array of shape"):
        pf.ekf_seed000([0, 0], I2, u, z, I2, I2, mask=[True])
    with pytest.raises(ValueError, match=r"dt\[1\] must be finite and >= 0"):
        pf.ekf_constant_velocity([0, 0, 0, 0], np.eye(4), [0.1, -0.1, 0.1, 0.1, 0.1], z, 1.0, I2)
    with pytest.raises(ValueError, match="integration must be 'exact_arc' or 'euler'"):
        pf.ekf_unicycle([0, 0, 0], np.eye(3), u, 0.1, np.ones((5, 3)), I2, np.eye(3), integration="rk4")
    with pytest.raises(ValueError, match="ekf_unicycle: control_cov: covariance is not symmetric"):
        pf.ekf_unicycle([0, 0, 0], np.eye(3), u, 0.1, np.ones((5, 3)), [[1, 1], [0, 1]], np.eye(3))
    with pytest.raises(ValueError, match="Se2Odometry: noise rates must be finite and >= 0"):
        pf.ekf_se2_odometry([0, 0, 0], np.eye(3), np.ones((5, 3)), np.ones((5, 3)), np.eye(3), xy_sigma_per_sqrt_m=-1)
    with pytest.raises(TypeError, match="got None"):
        pf.ekf_seed000(None, I2, u, z, I2, I2)
    with pytest.raises(TypeError):
        pf.rts_smooth(None)
    # non-contiguous and integer inputs give the same numbers
    u2 = np.ones((10, 2))[::2]
    a = pf.ekf_seed000([0, 0], I2, u2, np.asfortranarray(z), I2, I2)
    b = pf.ekf_seed000(np.array([0, 0]), np.eye(2, dtype=int), np.ones((5, 2)), z, I2, I2)
    np.testing.assert_array_equal(a.states, b.states)


def test_run_arrays_are_copies_so_the_run_stays_as_recorded():
    u = np.ones((6, 2))
    run = pf.ekf_seed000([0, 0], np.eye(2), u, np.cumsum(u, axis=0), np.eye(2) * 0.1, np.eye(2) * 0.1)
    ref = pf.rts_smooth(run)
    s = run.states
    s[:] = np.nan
    s.shape = (12,)
    np.testing.assert_array_equal(pf.rts_smooth(run)[0], ref[0])
    assert run.states.shape == (6, 2) and not np.isnan(run.states).any()
