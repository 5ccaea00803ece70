"""posefuse.preintegrate / Preintegration / ImuFactor / align_visual_inertial.

The pre-integration is checked against the mid-point rule written here in
numpy (inertial/preintegration.hpp's file comment); its bias Jacobian and
covariance against central differences of that numpy integration (the
covariance as sum_k J_k Q_k J_k^T over every step's noise inputs, the
discretisation of the file comment); the IMU factor's residual against its
formula and its Jacobians against central differences; the alignment on a
synthetic motion whose scale, gravity and gyroscope bias are known.
"""
import math

import numpy as np
import pytest

import posefuse as pf

G = np.array([0.0, 0.0, -9.81])


def expR(w):
    th = np.linalg.norm(w)
    K = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    if th < 1e-12:
        return np.eye(3) + K + 0.5 * K @ K
    return np.eye(3) + math.sin(th) / th * K + (1 - math.cos(th)) / th ** 2 * K @ K


def logR(R):
    return pf.SO3.log(pf.SO3.normalize(R))


def imu_stream(n=41, seed=5, rate=200.0):
    rng = np.random.default_rng(seed)
    t_ns = (np.arange(n) * (1e9 / rate)).astype(np.int64) + 1_000_000_000
    acc = np.c_[0.5 * np.sin(np.arange(n) / 7.0), 0.3 * np.cos(np.arange(n) / 5.0), 9.81 + 0.2 * np.sin(np.arange(n) / 3.0)]
    acc += rng.normal(0, 0.05, (n, 3))
    gyro = np.c_[0.3 * np.sin(np.arange(n) / 9.0), -0.2 + 0.01 * np.arange(n) / n, 0.8 * np.cos(np.arange(n) / 11.0)]
    gyro += rng.normal(0, 0.01, (n, 3))
    return t_ns, acc, gyro


def integrate_np(t_ns, acc, gyro, ba, bg, noise=None, walk=None):
    """Mid-point pre-integration; noise[k] = 12 inputs of step k (a_k, g_k, a_k+1, g_k+1),
    walk[k] = 6 bias random-walk inputs added after step k. Returns (dp, dR, dv, dba, dbg)."""
    dp, dv, dR = np.zeros(3), np.zeros(3), np.eye(3)
    dba, dbg = np.zeros(3), np.zeros(3)
    for k in range(len(t_ns) - 1):
        dt = (int(t_ns[k + 1]) - int(t_ns[k])) * 1e-9
        nz = np.zeros(12) if noise is None else noise[k]
        a0 = acc[k] + nz[0:3] - (ba + dba)
        a1 = acc[k + 1] + nz[6:9] - (ba + dba)
        w = 0.5 * (gyro[k] + nz[3:6] + gyro[k + 1] + nz[9:12]) - (bg + dbg)
        R1 = dR @ expR(w * dt)
        u = 0.5 * (dR @ a0 + R1 @ a1)
        dp = dp + dt * dv + 0.5 * dt * dt * u
        dv = dv + dt * u
        dR = R1
        if walk is not None:
            dba = dba + walk[k][:3]
            dbg = dbg + walk[k][3:]
    return dp, dR, dv, dba, dbg


def test_deltas_match_the_numpy_mid_point_rule():
    t, acc, gyro = imu_stream()
    ba, bg = np.array([0.1, -0.05, 0.02]), np.array([0.01, 0.02, -0.03])
    pre = pf.preintegrate(t, acc, gyro, bias_accel=ba, bias_gyro=bg)
    dp, dR, dv, _, _ = integrate_np(t, acc, gyro, ba, bg)
    np.testing.assert_allclose(pre.delta_p, dp, rtol=0, atol=1e-13)
    np.testing.assert_allclose(pre.delta_R, dR, rtol=0, atol=1e-13)
    np.testing.assert_allclose(pre.delta_v, dv, rtol=0, atol=1e-13)
    assert pre.dt == pytest.approx((t[-1] - t[0]) * 1e-9, rel=1e-14)
    assert pre.sample_count == len(t) and (pre.start_t_ns, pre.end_t_ns) == (t[0], t[-1])
    np.testing.assert_array_equal(pre.bias_accel, ba)
    # float seconds give the same integration as integer nanoseconds
    pre_s = pf.preintegrate(t * 1e-9, acc, gyro, bias_accel=ba, bias_gyro=bg)
    np.testing.assert_array_equal(pre_s.delta_p, pre.delta_p)


def test_bias_jacobian_and_first_order_correction_against_central_differences():
    t, acc, gyro = imu_stream()
    ba, bg = np.array([0.1, -0.05, 0.02]), np.array([0.01, 0.02, -0.03])
    pre = pf.preintegrate(t, acc, gyro, bias_accel=ba, bias_gyro=bg)
    _, R0, _, _, _ = integrate_np(t, acc, gyro, ba, bg)
    J = np.zeros((9, 6))
    eps = 1e-6
    for c in range(6):
        d = np.zeros(6)
        d[c] = eps
        p1, R1, v1, _, _ = integrate_np(t, acc, gyro, ba + d[:3], bg + d[3:])
        p2, R2, v2, _, _ = integrate_np(t, acc, gyro, ba - d[:3], bg - d[3:])
        J[:, c] = np.r_[(p1 - p2), logR(R0.T @ R1) - logR(R0.T @ R2), (v1 - v2)] / (2 * eps)
    np.testing.assert_allclose(pre.bias_jacobian, J, rtol=0, atol=1e-8)
    db = np.array([0.002, -0.001, 0.003, 0.0005, -0.0004, 0.0002])
    cp, cR, cv, Jc = pre.corrected(ba + db[:3], bg + db[3:], jacobian=True)
    Jb = pre.bias_jacobian
    np.testing.assert_allclose(cp, pre.delta_p + Jb[0:3] @ db, rtol=0, atol=1e-15)
    np.testing.assert_allclose(cR, pre.delta_R @ expR(Jb[3:6] @ db), rtol=0, atol=1e-14)
    np.testing.assert_allclose(cv, pre.delta_v + Jb[6:9] @ db, rtol=0, atol=1e-15)
    np.testing.assert_allclose(Jc[[0, 1, 2, 6, 7, 8]], Jb[[0, 1, 2, 6, 7, 8]], atol=0)
    # re-integration about the new bias lands close to the first-order correction
    assert pre.update_bias(ba + db[:3], bg + db[3:]) is False  # below the thresholds
    pre.reintegrate(ba + db[:3], bg + db[3:])
    np.testing.assert_allclose(pre.delta_p, cp, atol=1e-6)


def test_covariance_is_the_propagated_noise():
    t, acc, gyro = imu_stream(n=9)
    noise = pf.ImuNoise(gyro_noise_density=2e-3, accel_noise_density=3e-2, gyro_random_walk=4e-4,
                        accel_random_walk=5e-3)
    pre = pf.preintegrate(t, acc, gyro, noise=noise)
    P = pre.covariance
    np.testing.assert_array_equal(P, P.T)
    zero = pf.ImuNoise(0, 0, 0, 0)
    ba = bg = np.zeros(3)
    p0, R0, v0, _, _ = integrate_np(t, acc, gyro, ba, bg)
    steps = len(t) - 1
    ref = np.zeros((15, 15))
    eps = 1e-6
    for k in range(steps):
        dt = (int(t[k + 1]) - int(t[k])) * 1e-9
        q = np.r_[[2 * noise.accel_noise_density ** 2 / dt] * 3, [2 * noise.gyro_noise_density ** 2 / dt] * 3,
                  [2 * noise.accel_noise_density ** 2 / dt] * 3, [2 * noise.gyro_noise_density ** 2 / dt] * 3,
                  [noise.accel_random_walk ** 2 * dt] * 3, [noise.gyro_random_walk ** 2 * dt] * 3]
        Jk = np.zeros((15, 18))
        for c in range(18):
            outs = []
            for sgn in (1, -1):
                nz = np.zeros((steps, 12))
                wk = np.zeros((steps, 6))
                if c < 12:
                    nz[k, c] = sgn * eps
                else:
                    wk[k, c - 12] = sgn * eps
                p, R, v, dba, dbg = integrate_np(t, acc, gyro, ba, bg, nz, wk)
                outs.append(np.r_[p - p0, logR(R0.T @ R), v - v0, dba, dbg])
            Jk[:, c] = (outs[0] - outs[1]) / (2 * eps)
        ref += Jk @ np.diag(q) @ Jk.T
    # central differences carry ~1e-10 of the largest entry: tiny cross terms are compared to that
    np.testing.assert_allclose(P, ref, rtol=1e-6, atol=1e-8 * np.abs(ref).max())
    assert np.all(pf.preintegrate(t, acc, gyro, noise=zero).covariance == 0)


# ---- IMU factor ----------------------------------------------------------------

def factor_setup():
    t, acc, gyro = imu_stream()
    ba, bg = np.array([0.1, -0.05, 0.02]), np.array([0.01, 0.02, -0.03])
    pre = pf.preintegrate(t, acc, gyro, bias_accel=ba, bias_gyro=bg)
    f = pf.ImuFactor(pre, gravity=G)
    xi = pf.ImuState(p=[1.0, 2.0, 3.0], R=expR([0.1, -0.2, 0.3]), v=[0.5, -0.3, 0.2],
                     bias_accel=ba + [0.003, 0.0, -0.002], bias_gyro=bg + [0.0, 0.001, 0.0005])
    xj = pf.ImuState(p=[1.6, 1.8, 3.1], R=expR([0.15, -0.25, 0.5]), v=[0.8, -0.2, 0.1],
                     bias_accel=ba + [0.004, 0.0, 0.0], bias_gyro=bg)
    return pre, f, xi, xj


def test_imu_factor_residual_matches_its_formula():
    pre, f, xi, xj = factor_setup()
    T = pre.dt
    db = np.r_[xi.bias_accel - pre.bias_accel, xi.bias_gyro - pre.bias_gyro]
    Jb = pre.bias_jacobian
    dRb = pre.delta_R @ expR(Jb[3:6] @ db)
    Ri = xi.R
    r = np.r_[Ri.T @ (xj.p - xi.p - xi.v * T - 0.5 * G * T * T) - (pre.delta_p + Jb[0:3] @ db),
              logR(dRb.T @ Ri.T @ xj.R),
              Ri.T @ (xj.v - xi.v - G * T) - (pre.delta_v + Jb[6:9] @ db),
              xj.bias_accel - xi.bias_accel, xj.bias_gyro - xi.bias_gyro]
    np.testing.assert_allclose(f.residual(xi, xj), r, rtol=0, atol=1e-12)
    w = f.residual(xi, xj, whitened=True)
    assert w @ w == pytest.approx(r @ np.linalg.solve(f.covariance, r), rel=1e-12)
    np.testing.assert_allclose(f.whitening @ f.covariance @ f.whitening.T, np.eye(15), atol=1e-8)
    assert f.dt == pre.dt
    np.testing.assert_allclose(f.residual(xi, f.predict(xi)), np.zeros(15), atol=1e-12)


def test_imu_factor_jacobians_against_central_differences():
    _, f, xi, xj = factor_setup()
    r, Ji, Jj = f.residual(xi, xj, jacobians=True)
    num_i, num_j = np.zeros((15, 15)), np.zeros((15, 15))
    eps = 1e-6
    for c in range(15):
        d = np.zeros(15)
        d[c] = eps
        num_i[:, c] = (f.residual(xi.plus(d), xj) - f.residual(xi.plus(-d), xj)) / (2 * eps)
        num_j[:, c] = (f.residual(xi, xj.plus(d)) - f.residual(xi, xj.plus(-d))) / (2 * eps)
    np.testing.assert_allclose(Ji, num_i, atol=1e-6)
    np.testing.assert_allclose(Jj, num_j, atol=1e-6)
    rw, Jiw, Jjw = f.residual(xi, xj, jacobians=True, whitened=True)
    np.testing.assert_allclose(Jiw, f.whitening @ Ji, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(xj.minus(xi), np.r_[xj.p - xi.p, logR(xi.R.T @ xj.R), xj.v - xi.v,
                                                    xj.bias_accel - xi.bias_accel, xj.bias_gyro - xi.bias_gyro],
                               atol=1e-14)


# ---- alignment -------------------------------------------------------------------

def synthetic_run(n_key=6, spacing=0.5, rate=1000.0, bg_true=(0.01, -0.02, 0.005), excite=True):
    """Analytic body motion: p(t), R(t) = Exp(phi(t)); IMU = R^T (p'' - g) and Jr(phi) phi'."""
    T = (n_key - 1) * spacing
    t = np.arange(int(round(T * rate)) + 1) / rate

    def phi(x):
        return np.c_[0.2 * np.sin(x), 0.3 * np.sin(0.7 * x), 0.5 * x]

    def dphi(x):
        return np.c_[0.2 * np.cos(x), 0.21 * np.cos(0.7 * x), 0.5 * np.ones_like(x)]

    if excite:
        p = np.c_[2 * np.sin(1.3 * t), 1.5 * np.cos(0.9 * t), 0.5 * np.sin(2.1 * t)]
        acc_w = np.c_[-2 * 1.69 * np.sin(1.3 * t), -1.5 * 0.81 * np.cos(0.9 * t), -0.5 * 4.41 * np.sin(2.1 * t)]
        vel = np.c_[2 * 1.3 * np.cos(1.3 * t), -1.5 * 0.9 * np.sin(0.9 * t), 0.5 * 2.1 * np.cos(2.1 * t)]
    else:
        p = np.c_[t, 0 * t, 0 * t]
        acc_w = np.zeros_like(p)
        vel = np.c_[np.ones_like(t), 0 * t, 0 * t]
    R = pf.SO3.exp(phi(t))
    gyro = np.einsum("nij,nj->ni", pf.SO3.right_jacobian(phi(t)), dphi(t)) + np.asarray(bg_true)
    acc = np.einsum("nji,nj->ni", R, acc_w - G)
    keys = [int(round(k * spacing * rate)) for k in range(n_key)]
    T_w_b = pf.SE3.from_rt(R[keys], p[keys])
    return t, acc, gyro, keys, T_w_b, vel[keys]


@pytest.mark.parametrize("n_key", [4, 6, 12])
def test_alignment_recovers_scale_gravity_and_gyro_bias(n_key):
    t, acc, gyro, keys, T_w_b, vel = synthetic_run(n_key=n_key, spacing=0.5)
    T_b_c = pf.SE3.exp([0.05, -0.02, 0.1, -1.2, 0.1, 1.5])
    T_w_c = T_w_b @ T_b_c
    s_true = 2.5
    T_c0_c = np.linalg.inv(T_w_c[0]) @ T_w_c
    T_c0_c[:, :3, 3] /= s_true
    t_ns = np.round(t * 1e9).astype(np.int64)
    pres = [pf.preintegrate(t_ns[a:b + 1], acc[a:b + 1], gyro[a:b + 1]) for a, b in zip(keys[:-1], keys[1:])]
    before = pres[0].delta_p.copy()
    r = pf.align_visual_inertial(T_c0_c, T_b_c, pres)
    assert r["ok"], r["status"]
    assert r["scale"] == pytest.approx(s_true, rel=2e-3)
    np.testing.assert_allclose(r["gyro_bias"], [0.01, -0.02, 0.005], atol=2e-4)
    assert np.linalg.norm(r["gravity_c0"]) == pytest.approx(9.81, rel=1e-12)
    np.testing.assert_allclose(np.linalg.norm(r["velocity_w"], axis=1), np.linalg.norm(vel, axis=1), rtol=1e-2)
    Rw = r["T_w_b"][:, :3, :3]
    # world z up: the gravity direction of the aligned frame is -z
    np.testing.assert_allclose(r["R_w_c0"] @ r["gravity_c0"], [0, 0, -9.81], atol=1e-9)
    assert Rw.shape == (n_key, 3, 3)
    np.testing.assert_array_equal(pres[0].delta_p, before)  # the inputs were not modified
    np.testing.assert_allclose(r["preintegrations"][0].bias_gyro, r["gyro_bias"], atol=0)


def test_three_keyframes_are_refused():
    # 6 (N - 1) = 12 equations for 3 N + 4 = 13 unknowns: no motion makes three keyframes solvable
    t, acc, gyro, keys, T_w_b, _ = synthetic_run(n_key=3, spacing=0.8)
    t_ns = np.round(t * 1e9).astype(np.int64)
    pres = [pf.preintegrate(t_ns[a:b + 1], acc[a:b + 1], gyro[a:b + 1]) for a, b in zip(keys[:-1], keys[1:])]
    with pytest.raises(ValueError, match="3 keyframes; at least 4 are needed"):
        pf.align_visual_inertial(T_w_b, np.eye(4), pres)


def test_alignment_reports_insufficient_excitation():
    t, acc, gyro, keys, T_w_b, _ = synthetic_run(n_key=4, excite=False)
    t_ns = np.round(t * 1e9).astype(np.int64)
    pres = [pf.preintegrate(t_ns[a:b + 1], acc[a:b + 1], gyro[a:b + 1]) for a, b in zip(keys[:-1], keys[1:])]
    r = pf.align_visual_inertial(T_w_b, np.eye(4), pres)
    assert not r["ok"] and r["status"] == "insufficient excitation"
    with pytest.raises(ValueError, match="4 keyframes need 3 pre-integrations, got 2"):
        pf.align_visual_inertial(T_w_b, np.eye(4), pres[:2])
    with pytest.raises(ValueError, match="2 keyframes; at least 4 are needed"):
        pf.align_visual_inertial(T_w_b[:2], np.eye(4), pres[:1])


# ---- misuse ----------------------------------------------------------------------

def test_bad_input_raises_with_the_cpp_messages():
    t, acc, gyro = imu_stream(n=10)
    bad = t.copy()
    bad[5] = bad[3]
    with pytest.raises(ValueError, match=r"preintegrate: sample 5 \(t = \d+ ns\): out of order"):
        pf.preintegrate(bad, acc, gyro)
    bad[5] = bad[4]
    with pytest.raises(ValueError, match=r"sample 5 .*: repeated stamp"):
        pf.preintegrate(bad, acc, gyro)
    gap = t.copy()
    gap[6:] += 10**9
    with pytest.raises(ValueError, match="gap above the limit"):
        pf.preintegrate(gap, acc, gyro)
    a = acc.copy()
    a[2, 1] = np.nan
    with pytest.raises(ValueError, match=r"sample 2 .*: non-finite reading"):
        pf.preintegrate(t, a, gyro)
    with pytest.raises(ValueError, match=r"accel: expected an array of shape \(10, 3\), got \(9, 3\)"):
        pf.preintegrate(t, acc[:9], gyro)
    with pytest.raises(TypeError, match="got None"):
        pf.preintegrate(t, None, gyro)
    with pytest.raises(TypeError, match="expected integer \\(ns\\) or float \\(s\\) stamps"):
        pf.preintegrate(np.array(["a"] * 10), acc, gyro)
    with pytest.raises(ValueError, match="samples do not cover the interval"):
        pf.preintegrate(t, acc, gyro, t0=int(t[0]) - 5, t1=int(t[-1]))
    with pytest.raises(TypeError, match="t0: expected an integer time in ns, like t"):
        pf.preintegrate(t, acc, gyro, t0=float(t[1]), t1=int(t[-1]))
    with pytest.raises(ValueError, match="give both t0 and t1, or neither"):
        pf.preintegrate(t, acc, gyro, t0=int(t[1]))
    with pytest.raises(ValueError, match=r"ImuNoise: gyro_noise_density must be finite and >= 0, got -1"):
        pf.ImuNoise(gyro_noise_density=-1.0)
    with pytest.raises(ValueError, match="Preintegration: bias is not finite"):
        pf.preintegrate(t, acc, gyro, bias_accel=[np.nan, 0, 0])
    zero = pf.preintegrate(t, acc, gyro, noise=pf.ImuNoise(0, 0, 0, 0))
    with pytest.raises(ValueError, match="ImuFactor: the pre-integration covariance is not positive definite"):
        pf.ImuFactor(zero)
    with pytest.raises(ValueError, match="ImuFactor: gravity is not finite"):
        pf.ImuFactor(pf.preintegrate(t, acc, gyro), gravity=[0, 0, np.inf])
    with pytest.raises(ValueError, match="SO3: matrix is not orthonormal"):
        pf.ImuState(R=np.ones((3, 3)))
    with pytest.raises(TypeError):
        pf.ImuFactor(None)


def test_interval_cut_with_interpolated_ends():
    t, acc, gyro = imu_stream(n=21)
    t0 = int(t[2]) + 1_000_000  # between samples 2 and 3
    t1 = int(t[15])             # on a sample
    pre = pf.preintegrate(t, acc, gyro, t0=t0, t1=t1)
    assert (pre.start_t_ns, pre.end_t_ns) == (t0, t1)
    s = (t0 - int(t[2])) / (int(t[3]) - int(t[2]))
    ts = np.r_[t0, t[3:16]].astype(np.int64)
    a = np.vstack([acc[2] + s * (acc[3] - acc[2]), acc[3:16]])
    g = np.vstack([gyro[2] + s * (gyro[3] - gyro[2]), gyro[3:16]])
    dp, dR, dv, _, _ = integrate_np(ts, a, g, np.zeros(3), np.zeros(3))
    np.testing.assert_allclose(pre.delta_p, dp, atol=1e-13)
    np.testing.assert_allclose(pre.delta_R, dR, atol=1e-13)
    np.testing.assert_allclose(pre.delta_v, dv, atol=1e-13)


def test_euroc_windows_equal_imu_preintegration_check(data_dir):
    """imu_preintegration_check's windows rebuilt in Python on EuRoC V1_01_easy: the same
    pre-integration code, the error arithmetic in numpy: equal to 1e-12 relative."""
    import json
    import pathlib
    import subprocess

    d = data_dir / "euroc" / "V1_01_easy"
    if not (d / "imu0.csv").is_file() or not (d / "groundtruth_20hz.csv").is_file():
        pytest.skip("EuRoC V1_01_easy imu0.csv / groundtruth_20hz.csv not found under %s" % d)
    prog = pathlib.Path(pf.__file__).resolve().parents[1] / "examples" / "imu_preintegration_check"
    if not prog.is_file():
        pytest.skip("imu_preintegration_check not built at %s" % prog)
    proc = subprocess.run([str(prog), "--imu", str(d / "imu0.csv"), "--groundtruth", str(d / "groundtruth_20hz.csv"),
                           "--window", "1", "--json"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    ref = json.loads(proc.stdout)
    imu = np.loadtxt(d / "imu0.csv", delimiter=",", comments="#", dtype=np.float64)
    t_imu = np.loadtxt(d / "imu0.csv", delimiter=",", comments="#", usecols=0, dtype=np.int64)
    gt = np.loadtxt(d / "groundtruth_20hz.csv", delimiter=",", comments="#", dtype=np.float64)
    t_gt = np.loadtxt(d / "groundtruth_20hz.csv", delimiter=",", comments="#", usecols=0, dtype=np.int64)
    R = pf.SO3.from_quaternion(gt[:, 4:8])
    steps = np.diff(t_gt)
    step = int(np.partition(steps, len(steps) // 2)[len(steps) // 2])
    window = 10 ** 9
    pos, rot, vel, nees = [], [], [], []
    i = 0
    while i + 1 < len(t_gt):
        j = i + 1
        while j < len(t_gt) and t_gt[j] - t_gt[i] < window - step // 2:
            j += 1
        if j == len(t_gt):
            break
        start, i = i, j
        if np.any(np.diff(t_gt[start:j + 1]) > 2.5 * step):
            continue
        pre = pf.preintegrate(t_imu, imu[:, 4:7], imu[:, 1:4], bias_accel=gt[start, 14:17],
                              bias_gyro=gt[start, 11:14], t0=int(t_gt[start]), t1=int(t_gt[j]))
        T = pre.dt
        Ri = R[start]
        dp = Ri.T @ (gt[j, 1:4] - gt[start, 1:4] - gt[start, 8:11] * T - 0.5 * G * T * T)
        dv = Ri.T @ (gt[j, 8:11] - gt[start, 8:11] - G * T)
        e = np.r_[dp - pre.delta_p, pf.SO3.log(pre.delta_R.T @ Ri.T @ R[j]), dv - pre.delta_v]
        P = pre.covariance[:9, :9]
        pos.append(np.linalg.norm(e[:3]))
        rot.append(np.degrees(np.linalg.norm(e[3:6])))
        vel.append(np.linalg.norm(e[6:]))
        nees.append(e @ np.linalg.solve(P, e))
    assert len(pos) == ref["windows"]
    rms = lambda v: math.sqrt(np.mean(np.square(v)))  # noqa: E731
    assert rms(pos) == pytest.approx(ref["position_error_rmse"], rel=1e-12)
    assert max(pos) == pytest.approx(ref["position_error_max"], rel=1e-12)
    assert rms(rot) == pytest.approx(ref["rotation_error_rmse_deg"], rel=1e-12)
    assert rms(vel) == pytest.approx(ref["velocity_error_rmse"], rel=1e-12)
    assert np.mean(nees) == pytest.approx(ref["nees_mean"], rel=1e-12)
