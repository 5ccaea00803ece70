"""posefuse.SO2 / SE2 / SO3 / SE3 against independent numpy formulas.

Exp is checked against the matrix exponential of hat(tau) (scaling and
squaring of the Taylor series, written here), Log by the round trip, and
every Jacobian against central differences of the same numpy formulas with
right perturbations, x (+) t = x Exp(t) (lie/lie.hpp).
"""
import math

import numpy as np
import pytest

import posefuse as pf

RNG = np.random.default_rng(21)


# ---- independent numpy reference -------------------------------------------

def skew(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def hat(group, tau):
    tau = np.atleast_1d(np.asarray(tau, float))
    if group == "SO2":
        return np.array([[0.0, -tau[0]], [tau[0], 0.0]])
    if group == "SE2":
        return np.array([[0.0, -tau[2], tau[0]], [tau[2], 0.0, tau[1]], [0.0, 0.0, 0.0]])
    if group == "SO3":
        return skew(tau)
    W = np.zeros((4, 4))
    W[:3, :3] = skew(tau[3:])
    W[:3, 3] = tau[:3]
    return W


def vee(group, W):
    if group == "SO2":
        return np.array([W[1, 0]])
    if group == "SE2":
        return np.array([W[0, 2], W[1, 2], W[1, 0]])
    if group == "SO3":
        return np.array([W[2, 1], W[0, 2], W[1, 0]])
    return np.concatenate([W[:3, 3], [W[2, 1], W[0, 2], W[1, 0]]])


def expm(A):
    """Matrix exponential: scaling and squaring of a 30-term Taylor series."""
    n = max(0, int(math.ceil(math.log2(max(np.abs(A).sum(), 1e-300)))) + 1)
    B = A / (2.0 ** n)
    E = np.eye(A.shape[0])
    term = np.eye(A.shape[0])
    for k in range(1, 30):
        term = term @ B / k
        E = E + term
    for _ in range(n):
        E = E @ E
    return E


def logm_near_identity(M):
    """log(M) for M close to the identity (series of log(I + A))."""
    A = M - np.eye(M.shape[0])
    L = np.zeros_like(A)
    P = np.eye(M.shape[0])
    for k in range(1, 40):
        P = P @ A
        L = L + ((-1) ** (k + 1)) * P / k
    return L


DIM = {"SO2": 1, "SE2": 3, "SO3": 3, "SE3": 6}
PDIM = {"SO2": 2, "SE2": 2, "SO3": 3, "SE3": 3}
GROUPS = ["SO2", "SE2", "SO3", "SE3"]


def G(name):
    return getattr(pf, name)


def np_exp(group, tau):
    return expm(hat(group, tau))


def np_minus(group, Y, X):
    """Log(X^-1 Y) for Y close to X."""
    return vee(group, logm_near_identity(np.linalg.solve(X, Y)))


def as_tangent(group, t):
    """The module's tangent layout: a scalar for SO2."""
    return float(t[0]) if group == "SO2" else np.asarray(t, float)


def tangent_vec(group, t):
    return np.atleast_1d(np.asarray(t, float))


def random_tangent(group, scale=1.0):
    """A tangent vector whose rotation angle stays below 3 rad (Log's range is [0, pi])."""
    t = RNG.normal(size=DIM[group]) * scale
    rot = {"SO2": slice(0, 1), "SE2": slice(2, 3), "SO3": slice(0, 3), "SE3": slice(3, 6)}[group]
    n = np.linalg.norm(t[rot])
    if n > 3.0:
        t[rot] *= 3.0 / n
    return t


def random_element(group):
    return np_exp(group, random_tangent(group))


def num_jac_group_to_group(group, f, x, eps=1e-6):
    """d[f(x Exp(e)) (-) f(x)]/de for f: group -> group."""
    d = DIM[group]
    fx = f(x)
    J = np.zeros((d, d))
    for k in range(d):
        e = np.zeros(d)
        e[k] = eps
        fp = f(x @ np_exp(group, e))
        fm = f(x @ np_exp(group, -e))
        J[:, k] = (np_minus(group, fp, fx) - np_minus(group, fm, fx)) / (2 * eps)
    return J


# ---- exp / log ---------------------------------------------------------------

@pytest.mark.parametrize("group", GROUPS)
@pytest.mark.parametrize("scale", [1e-9, 1e-3, 0.3, 1.0, 2.5])
def test_exp_matches_matrix_exponential_and_log_inverts_it(group, scale):
    for _ in range(5):
        tau = random_tangent(group, scale)
        g = G(group).exp(as_tangent(group, tau))
        assert g.shape == {"SO2": (2, 2), "SE2": (3, 3), "SO3": (3, 3), "SE3": (4, 4)}[group]
        np.testing.assert_allclose(g, np_exp(group, tau), rtol=0, atol=1e-12)
        back = tangent_vec(group, G(group).log(g))
        np.testing.assert_allclose(back, tau, rtol=0, atol=1e-12 * max(1.0, np.abs(tau).max()))


def test_so3_log_at_pi_and_closed_forms():
    axis = np.array([1.0, 2.0, -2.0]) / 3.0
    R = pf.SO3.exp(math.pi * axis)
    phi = pf.SO3.log(R)
    assert abs(np.linalg.norm(phi) - math.pi) < 1e-12
    assert min(np.abs(phi - math.pi * axis).max(), np.abs(phi + math.pi * axis).max()) < 1e-12
    # Rodrigues' formula
    w = np.array([0.3, -0.2, 0.9])
    th = np.linalg.norm(w)
    K = skew(w / th)
    R_ref = np.eye(3) + math.sin(th) * K + (1 - math.cos(th)) * K @ K
    np.testing.assert_allclose(pf.SO3.exp(w), R_ref, rtol=0, atol=1e-15 * 10)


def test_so2_and_se2_closed_forms():
    th = 0.7
    np.testing.assert_allclose(pf.SO2.exp(th), [[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]],
                               rtol=0, atol=1e-16)
    assert abs(float(pf.SO2.log(pf.SO2.exp(3.0))) - 3.0) < 1e-15
    assert abs(float(pf.SO2.angle(pf.SO2.from_angle(-3.5))) - (2 * math.pi - 3.5)) < 1e-14
    T = pf.SE2.from_xytheta([1.0, -2.0, 0.5])
    np.testing.assert_allclose(pf.SE2.to_xytheta(T), [1.0, -2.0, 0.5], rtol=0, atol=1e-15)


# ---- Jacobians by central differences -----------------------------------------

@pytest.mark.parametrize("group", GROUPS)
def test_jacobians_against_central_differences(group):
    M = G(group)
    d = DIM[group]
    tau = random_tangent(group, 0.8)
    a, b = random_element(group), random_element(group)

    _, Jr = M.exp(as_tangent(group, tau), jacobian=True)
    num = np.zeros((d, d))
    for k in range(d):
        e = np.zeros(d)
        e[k] = 1e-6
        num[:, k] = (np_minus(group, np_exp(group, tau + e), np_exp(group, tau))
                     - np_minus(group, np_exp(group, tau - e), np_exp(group, tau))) / 2e-6
    np.testing.assert_allclose(Jr, num, atol=1e-8)
    np.testing.assert_allclose(M.right_jacobian(as_tangent(group, tau)), Jr, atol=0)
    np.testing.assert_allclose(M.left_jacobian(as_tangent(group, tau)),
                               M.right_jacobian(as_tangent(group, -tau)), atol=0)
    np.testing.assert_allclose(M.right_jacobian_inverse(as_tangent(group, tau)) @ Jr, np.eye(d), atol=1e-12)
    np.testing.assert_allclose(M.left_jacobian_inverse(as_tangent(group, tau)) @ M.left_jacobian(as_tangent(group, tau)),
                               np.eye(d), atol=1e-12)

    g = np_exp(group, tau)
    t_back, Jl = M.log(g, jacobian=True)
    np.testing.assert_allclose(Jl, np.linalg.inv(Jr), atol=1e-10)

    inv, J_inv = M.inverse(a, jacobian=True)
    np.testing.assert_allclose(inv, np.linalg.inv(a), atol=1e-12)
    np.testing.assert_allclose(J_inv, num_jac_group_to_group(group, np.linalg.inv, a), atol=1e-7)

    c, Jca, Jcb = M.compose(a, b, jacobians=True)
    np.testing.assert_allclose(c, a @ b, atol=1e-12)
    np.testing.assert_allclose(Jca, num_jac_group_to_group(group, lambda x: x @ b, a), atol=1e-7)
    np.testing.assert_allclose(Jcb, num_jac_group_to_group(group, lambda x: a @ x, b), atol=1e-7)

    dd, Jda, Jdb = M.between(a, b, jacobians=True)
    np.testing.assert_allclose(dd, np.linalg.solve(a, b), atol=1e-12)
    np.testing.assert_allclose(Jda, num_jac_group_to_group(group, lambda x: np.linalg.solve(x, b), a), atol=1e-7)
    np.testing.assert_allclose(Jdb, num_jac_group_to_group(group, lambda x: np.linalg.solve(a, x), b), atol=1e-7)

    y, Jyx, Jyt = M.plus(a, as_tangent(group, tau), jacobians=True)
    np.testing.assert_allclose(y, a @ np_exp(group, tau), atol=1e-12)
    np.testing.assert_allclose(Jyx, num_jac_group_to_group(group, lambda x: x @ np_exp(group, tau), a), atol=1e-7)
    np.testing.assert_allclose(Jyt, Jr, atol=1e-12)

    dm, Jdy, Jdx = M.minus(b, a, jacobians=True)
    dm = tangent_vec(group, dm)
    np.testing.assert_allclose(dm, tangent_vec(group, M.log(np.linalg.solve(a, b))), atol=1e-12)
    num_y = np.zeros((d, d))
    num_x = np.zeros((d, d))
    for k in range(d):
        e = np.zeros(d)
        e[k] = 1e-6
        num_y[:, k] = (tangent_vec(group, M.minus(b @ np_exp(group, e), a))
                       - tangent_vec(group, M.minus(b @ np_exp(group, -e), a))) / 2e-6
        num_x[:, k] = (tangent_vec(group, M.minus(b, a @ np_exp(group, e)))
                       - tangent_vec(group, M.minus(b, a @ np_exp(group, -e)))) / 2e-6
    np.testing.assert_allclose(Jdy, num_y, atol=1e-7)
    np.testing.assert_allclose(Jdx, num_x, atol=1e-7)

    # adjoint: g hat(t) g^-1 = hat(Ad_g t)
    Ad = M.adjoint(a)
    np.testing.assert_allclose(hat(group, Ad @ tau), a @ hat(group, tau) @ np.linalg.inv(a), atol=1e-12)

    # act
    p = RNG.normal(size=PDIM[group])
    q, Jqg, Jqp = M.act(a, p, jacobians=True)
    P = PDIM[group]
    hom = group in ("SE2", "SE3")

    def act_np(g, pt):
        return g[:P, :P] @ pt + (g[:P, P] if hom else 0.0)

    np.testing.assert_allclose(q, act_np(a, p), atol=1e-12)
    numg = np.zeros((P, d))
    for k in range(d):
        e = np.zeros(d)
        e[k] = 1e-6
        numg[:, k] = (act_np(a @ np_exp(group, e), p) - act_np(a @ np_exp(group, -e), p)) / 2e-6
    np.testing.assert_allclose(Jqg, numg, atol=1e-8)
    np.testing.assert_allclose(Jqp, a[:P, :P], atol=1e-12)

    # hat / vee
    np.testing.assert_allclose(M.hat(as_tangent(group, tau)), hat(group, tau), atol=0)
    np.testing.assert_allclose(tangent_vec(group, M.vee(hat(group, tau))), tau, atol=0)
    np.testing.assert_array_equal(M.identity(), np.eye(a.shape[0]))


# ---- vectorisation, broadcasting, layouts --------------------------------------

@pytest.mark.parametrize("group", GROUPS)
def test_stacks_equal_single_calls_bit_for_bit(group):
    M = G(group)
    taus = RNG.normal(size=(2, 3, DIM[group])) if group != "SO2" else RNG.normal(size=(2, 3))
    gs = M.exp(taus)
    assert gs.shape[:2] == (2, 3)
    for i in range(2):
        for j in range(3):
            np.testing.assert_array_equal(gs[i, j], M.exp(taus[i, j]))
    a = gs[0, 0]
    c = M.compose(a, gs)  # one element against a stack
    for i in range(2):
        for j in range(3):
            np.testing.assert_array_equal(c[i, j], M.compose(a, gs[i, j]))
    with pytest.raises(ValueError, match="do not match"):
        M.compose(gs, gs[0, :2])


def test_non_contiguous_fortran_and_int_inputs_give_the_same_numbers():
    taus = RNG.normal(size=(6, 3))
    ref = pf.SO3.exp(taus[::2])
    np.testing.assert_array_equal(pf.SO3.exp(np.ascontiguousarray(taus[::2])), ref)
    np.testing.assert_array_equal(pf.SO3.exp(taus[::2]), ref)
    R = pf.SO3.exp(taus)
    np.testing.assert_array_equal(pf.SO3.log(np.asfortranarray(R)), pf.SO3.log(R))
    np.testing.assert_array_equal(pf.SO3.exp([1, 2, 3]), pf.SO3.exp(np.array([1.0, 2.0, 3.0])))
    np.testing.assert_array_equal(pf.SE3.inverse(np.eye(4, dtype=np.int32)), np.eye(4))


def test_quaternions_and_from_rt():
    q = np.array([0.9, 0.1, -0.3, 0.2])
    R = pf.SO3.from_quaternion(q)
    qn = q / np.linalg.norm(q)
    w, x, y, z = qn
    R_ref = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                      [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                      [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    np.testing.assert_allclose(R, R_ref, atol=1e-15 * 10)
    np.testing.assert_allclose(pf.SO3.to_quaternion(R), qn, atol=1e-15 * 10)
    np.testing.assert_allclose(pf.SO3.from_quaternion(np.roll(q, -1), order="xyzw"), R, atol=0)
    np.testing.assert_allclose(pf.SO3.to_quaternion(R, order="xyzw"), np.roll(qn, -1), atol=1e-15 * 10)
    assert pf.SO3.to_quaternion(pf.SO3.from_quaternion(-q))[0] > 0
    T = pf.SE3.from_rt(R, [1.0, 2.0, 3.0])
    np.testing.assert_allclose(T[:3, :3], R, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(T[:3, 3], [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(T[3], [0, 0, 0, 1])


# ---- bad input ---------------------------------------------------------------

def test_bad_input_raises_with_the_cpp_messages():
    with pytest.raises(ValueError, match=r"SO3: matrix is not orthonormal \(max \|R\^T R - I\| = "):
        pf.SO3.log(np.ones((3, 3)))
    with pytest.raises(ValueError, match=r"SO3: matrix is a reflection \(det <= 0\), not a rotation"):
        pf.SO3.log(-np.eye(3))
    with pytest.raises(ValueError, match="SO3: rotation matrix has a non-finite entry"):
        pf.SO3.inverse(np.full((3, 3), np.nan))
    with pytest.raises(ValueError, match="SE3: translation has a non-finite entry"):
        T = np.eye(4)
        T[0, 3] = np.inf
        pf.SE3.log(T)
    with pytest.raises(ValueError, match="SO3: rotation matrix has a non-finite entry"):
        T = np.eye(4)
        T[1, 1] = np.nan
        pf.SE3.log(T)
    with pytest.raises(ValueError, match="SE2: translation has a non-finite entry"):
        T = np.eye(3)
        T[1, 2] = np.nan
        pf.SE2.log(T)
    with pytest.raises(ValueError, match=r"SE2: bottom row of the matrix is not \[0 0 1\]"):
        pf.SE2.log(np.ones((3, 3)))
    with pytest.raises(ValueError, match=r"SE3: bottom row of the matrix is not \[0 0 0 1\]"):
        T = np.eye(4)
        T[3, 0] = 1
        pf.SE3.log(T)
    with pytest.raises(ValueError, match="SO3: quaternion has \\(near\\) zero norm"):
        pf.SO3.from_quaternion([0.0, 0, 0, 0])
    with pytest.raises(ValueError, match="SO3: quaternion has a non-finite coefficient"):
        pf.SO3.from_quaternion([np.nan, 0, 0, 1])
    with pytest.raises(ValueError, match=r"SO3.log: g: expected an array of shape \(\.\.\., 3, 3\), got \(4, 3\)"):
        pf.SO3.log(np.zeros((4, 3)))
    with pytest.raises(ValueError, match=r"SE2.exp: tau: expected an array of shape \(\.\.\., 3\)"):
        pf.SE2.exp(np.zeros(2))
    with pytest.raises(ValueError, match="SO2: matrix is not orthonormal"):
        pf.SO2.log(2 * np.eye(2))
    with pytest.raises(ValueError, match="order must be 'wxyz' or 'xyzw'"):
        pf.SO3.from_quaternion([1.0, 0, 0, 0], order="zyxw")
    with pytest.raises(TypeError, match="got None"):
        pf.SE3.exp(None)
    with pytest.raises(TypeError, match="cannot be converted to a float64 array"):
        pf.SO3.exp("abc")
    with pytest.raises(TypeError):
        pf.SO3.exp(np.zeros(3), jacobian="yes please")


@pytest.mark.parametrize("k", [30, 100, 500, 996, 1022])
def test_so3_and_se3_exp_of_huge_finite_rotation_vectors_are_rotations(k):
    # |phi| = 3 * 2^k exactly (axis (1, 2, 2) / 3); 3 * 2^1022 is near the largest double.
    u = np.array([1.0, 2.0, 2.0]) / 3.0
    phi = math.ldexp(1.0, k) * np.array([1.0, 2.0, 2.0])
    th = 3.0 * math.ldexp(1.0, k)
    R, J = pf.SO3.exp(phi, jacobian=True)
    assert np.isfinite(R).all() and np.isfinite(J).all()
    np.testing.assert_allclose(R.T @ R, np.eye(3), rtol=0, atol=1e-15)
    np.testing.assert_allclose(R @ u, u, rtol=0, atol=1e-15)  # about u ...
    assert abs(np.trace(R) - (1.0 + 2.0 * math.cos(th))) < 4e-15  # ... by th (cos reduces th exactly)
    np.testing.assert_allclose(J @ u, u, rtol=0, atol=1e-15)  # J_r(phi) phi = phi
    rho = np.array([0.3, -1.5, 2.0])
    T, JT = pf.SE3.exp(np.concatenate([rho, phi]), jacobian=True)
    assert np.isfinite(T).all() and np.isfinite(JT).all()
    np.testing.assert_array_equal(T[:3, :3], R)
    # t = J_l(phi) rho = u u^T rho + (sin th / th)(rho - u u^T rho) + ((1 - cos th) / th) u x rho:
    # the part of rho along the axis, within 3 |rho| / th.
    np.testing.assert_allclose(T[:3, 3], u * (u @ rho), rtol=0, atol=3 * np.linalg.norm(rho) / th + 1e-14)


def test_exp_of_a_rotation_vector_of_norm_1e300_is_a_rotation():
    phi = np.array([0.6e300, -0.8e300, 0.0])
    for R in (pf.SO3.exp(phi), pf.SE3.exp(np.concatenate([[1.0, 2.0, 3.0], phi]))[:3, :3]):
        assert np.isfinite(R).all()
        np.testing.assert_allclose(R.T @ R, np.eye(3), rtol=0, atol=1e-15)
        assert abs(np.linalg.det(R) - 1.0) < 1e-15
        np.testing.assert_allclose(R @ [0.6, -0.8, 0.0], [0.6, -0.8, 0.0], rtol=0, atol=1e-15)


def test_tangents_and_points_are_not_validated_nan_in_nan_out():
    assert np.isnan(pf.SO3.exp([np.nan, 0.0, 0.0])).all()
    assert np.isnan(pf.SE3.act(np.eye(4), [np.nan, 0.0, 0.0])[0])


@pytest.mark.parametrize("group", GROUPS)
def test_misuse_sweep_raises_never_crashes(group):
    M = G(group)
    one = ["exp", "log", "inverse", "adjoint", "right_jacobian", "right_jacobian_inverse", "left_jacobian",
           "left_jacobian_inverse", "hat", "vee", "normalize"]
    two = ["compose", "between", "act", "plus", "minus"]
    junk = [None, "abc", object(), np.zeros((2, 5, 7)), np.array([[1, 2], [3]], dtype=object)]
    takes_tangent = {"exp", "right_jacobian", "right_jacobian_inverse", "left_jacobian", "left_jacobian_inverse",
                     "hat", "plus"}
    for name in one:
        for j in junk:
            if group == "SO2" and name in takes_tangent and isinstance(j, np.ndarray) and j.dtype != object:
                continue  # SO2 tangents are scalars: any numeric shape is a stack of angles
            with pytest.raises((TypeError, ValueError)):
                getattr(M, name)(j)
    good = M.identity()
    for name in two:
        for j in junk:
            with pytest.raises((TypeError, ValueError)):
                getattr(M, name)(j, j)
            if group == "SO2" and name in takes_tangent and isinstance(j, np.ndarray) and j.dtype != object:
                continue
            with pytest.raises((TypeError, ValueError)):
                getattr(M, name)(good, j)
    # empty stacks are fine
    empty = M.exp(np.zeros((0,) + ((DIM[group],) if group != "SO2" else ())))
    assert empty.shape[0] == 0
    assert M.compose(good, empty).shape == empty.shape


def test_type_stubs_name_exactly_what_the_module_binds():
    import ast
    import pathlib

    stub = pathlib.Path(pf.__file__).resolve().parent / "_posefuse.pyi"
    tree = ast.parse(stub.read_text())
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    base = {n.name for n in classes.pop("_LieGroup").body if isinstance(n, ast.FunctionDef)}
    funcs = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    for name in funcs:
        assert callable(getattr(pf, name)), name
    for name, node in classes.items():
        cls = getattr(pf, name)
        if issubclass(cls, BaseException):
            continue  # exceptions: their stub declares the bases only
        declared = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        declared |= {n.target.id for n in node.body if isinstance(n, ast.AnnAssign)}
        if any(isinstance(b, ast.Name) and b.id == "_LieGroup" for b in node.bases):
            declared |= base
        runtime = {a for a in dir(cls) if not a.startswith("_")}
        public = {d for d in declared if not d.startswith("_")}
        assert public == runtime, (name, public ^ runtime)
