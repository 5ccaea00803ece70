"""posefuse.PoseGraph4Dof / PoseGraphSE3 / read_g2o / write_g2o.

Costs are checked against g2o's chi2 written here in numpy; the optimised
graphs against the C++ program optimize_pose_graph on the same g2o file (its
--json numbers and --out poses are printed as the shortest text that reads
back exactly, so the comparison is exact: the same code path).
"""
import json
import math
import pathlib
import subprocess

import numpy as np
import pytest

import posefuse as pf

RNG = np.random.default_rng(3)


def _program(name):
    path = pathlib.Path(pf.__file__).resolve().parents[1] / "examples" / name
    if not path.is_file():
        pytest.skip("%s not built at %s (build the examples)" % (name, path))
    return path


def wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def rot2(t):
    return np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])


def rotz(t):
    R = np.eye(3)
    R[:2, :2] = rot2(t)
    return R


def rot_xyz(roll, pitch, yaw):
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    return rotz(yaw) @ Ry @ Rx


# ---- planar graph (a track with loop closures), written as g2o text here ------

def planar_graph(n=60):
    truth = np.zeros((n, 3))
    for k in range(1, n):
        truth[k, 2] = wrap(truth[k - 1, 2] + 2 * math.pi / 20)
        truth[k, :2] = truth[k - 1, :2] + rot2(truth[k - 1, 2]) @ np.array([1.0, 0.0])
    edges = []
    for k in range(n - 1):
        edges.append((k, k + 1))
    for k in range(0, n - 20, 3):
        edges.append((k, k + 20))
    meas = []
    for i, j in edges:
        d = rot2(truth[i, 2]).T @ (truth[j, :2] - truth[i, :2])
        meas.append([d[0] + RNG.normal(0, 0.05), d[1] + RNG.normal(0, 0.05),
                     wrap(truth[j, 2] - truth[i, 2] + RNG.normal(0, 0.01))])
    # start: chained noisy odometry
    start = np.zeros((n, 3))
    for k in range(1, n):
        dx, dy, dt = meas[k - 1]
        start[k, :2] = start[k - 1, :2] + rot2(start[k - 1, 2]) @ np.array([dx, dy])
        start[k, 2] = wrap(start[k - 1, 2] + dt)
    info = np.array([[400.0, 10.0, 0.0], [10.0, 400.0, 0.0], [0.0, 0.0, 10000.0]])
    return start, edges, np.array(meas), info


def write_planar_g2o(path, poses, edges, meas, info):
    with open(path, "w") as f:
        for k, (x, y, t) in enumerate(poses):
            f.write("VERTEX_SE2 %d %r %r %r\n" % (k, x, y, t))
        for (i, j), (dx, dy, dt) in zip(edges, meas):
            u = [info[0, 0], info[0, 1], info[0, 2], info[1, 1], info[1, 2], info[2, 2]]
            f.write("EDGE_SE2 %d %d %r %r %r %s\n" % (i, j, dx, dy, dt, " ".join(repr(v) for v in u)))


def planar_chi2(poses, edges, meas, info):
    total = 0.0
    for (i, j), (dx, dy, dt) in zip(edges, meas):
        et = rot2(dt).T @ (rot2(poses[i, 2]).T @ (poses[j, :2] - poses[i, :2]) - np.array([dx, dy]))
        e = np.array([et[0], et[1], wrap(poses[j, 2] - poses[i, 2] - dt)])
        total += e @ info @ e
    return total


def test_planar_graph_cost_matches_g2o_chi2(tmp_path):
    poses, edges, meas, info = planar_graph()
    f = tmp_path / "planar.g2o"
    write_planar_g2o(f, poses, edges, meas, info)
    g = pf.read_g2o(f)
    assert isinstance(g, pf.PoseGraph4Dof)
    assert g.num_nodes == len(poses) and g.num_edges == len(edges) and g.is_planar()
    np.testing.assert_array_equal(g.ids, np.arange(len(poses)))
    np.testing.assert_array_equal(g.poses[:, [0, 1, 3]], poses)
    assert g.cost() == pytest.approx(planar_chi2(poses, edges, meas, info), rel=1e-12)
    # The same graph from arrays: the same cost, bit for bit.
    h = pf.PoseGraph4Dof()
    h.add_nodes(np.arange(len(poses)), poses)
    h.add_edges([e[0] for e in edges], [e[1] for e in edges], meas[:, :2], meas[:, 2], info)
    assert h.cost() == g.cost()
    np.testing.assert_array_equal(h.edges["information"], g.edges["information"])


def test_planar_graph_optimisation_equals_the_cpp_program(tmp_path):
    prog = _program("optimize_pose_graph")
    poses, edges, meas, info = planar_graph()
    f = tmp_path / "planar.g2o"
    write_planar_g2o(f, poses, edges, meas, info)
    out = tmp_path / "opt.g2o"
    proc = subprocess.run([str(prog), "--input", str(f), "--json", "--out", str(out)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    ref = json.loads(proc.stdout)
    g = pf.read_g2o(f)
    assert g.cost() == ref["file_cost"]
    g.initialize_rotation_first()
    assert g.cost() == ref["initial_cost"]
    s = g.optimize()
    assert s.final_cost == ref["final_cost"]
    assert s.iterations == ref["iterations"]
    assert s.termination == ref["termination"]
    assert s.planar and s.initial_cost == ref["initial_cost"]
    np.testing.assert_array_equal(g.poses, pf.read_g2o(out).poses)
    assert s.final_cost < 0.1 * ref["file_cost"]  # the loop closures undo the chained odometry's drift
    # Gauss-Newton and the 4x4 path reach the same optimum
    h = pf.read_g2o(f)
    h.initialize_rotation_first()
    s2 = h.optimize(method="gn", planar_fast_path=False)
    assert not s2.planar
    assert s2.final_cost == pytest.approx(s.final_cost, rel=1e-6)


def test_four_dof_cost_with_roll_pitch_and_z():
    n = 5
    poses = RNG.normal(size=(n, 4))
    rp = RNG.normal(scale=0.1, size=(n, 2))
    g = pf.PoseGraph4Dof()
    g.add_nodes(np.arange(10, 10 + n), poses, fixed=[True] + [False] * (n - 1), roll_pitch=rp)
    I = np.diag([10.0, 20.0, 30.0, 40.0])
    I[0, 3] = I[3, 0] = 1.0
    dp = RNG.normal(size=(n - 1, 3))
    dyaw = RNG.normal(size=n - 1)
    g.add_edges(np.arange(10, 9 + n), np.arange(11, 10 + n), dp, dyaw, np.broadcast_to(I, (n - 1, 4, 4)))
    ref = 0.0
    for k in range(n - 1):
        Ri = rot_xyz(rp[k, 0], rp[k, 1], poses[k, 3])
        et = rotz(dyaw[k]).T @ (Ri.T @ (poses[k + 1, :3] - poses[k, :3]) - dp[k])
        e = np.r_[et, wrap(poses[k + 1, 3] - poses[k, 3] - dyaw[k])]
        ref += e @ I @ e
    assert g.cost() == pytest.approx(ref, rel=1e-12)
    assert not g.is_planar()
    np.testing.assert_array_equal(g.roll_pitch, rp)
    np.testing.assert_array_equal(g.fixed, [True] + [False] * (n - 1))
    s = g.optimize()
    assert s.final_cost < 1e-20 and not s.planar  # a chain: every edge can be met exactly
    np.testing.assert_array_equal(g.pose(10), poses[0])  # the fixed node did not move
    g.set_pose(11, [1.0, 2.0, 3.0, 0.5])
    np.testing.assert_array_equal(g.pose(11), [1.0, 2.0, 3.0, 0.5])
    np.testing.assert_array_equal(g.roll_pitch[1], rp[1])
    with pytest.raises(ValueError, match="not planar"):
        pf.write_g2o("unused.g2o", g)


def test_robust_losses_change_the_cost_as_documented():
    g = pf.PoseGraph4Dof()
    g.add_node(0, [0.0, 0.0, 0.0])
    g.add_node(1, [3.0, 0.0, 0.0])
    g.add_edge(0, 1, [0.0, 0.0], 0.0, np.eye(3), loss="huber", loss_scale=1.0)
    s = 9.0
    assert g.cost() == pytest.approx(2 * 1.0 * math.sqrt(s) - 1.0, rel=1e-15)
    h = pf.PoseGraph4Dof()
    h.add_node(0, [0.0, 0.0, 0.0])
    h.add_node(1, [3.0, 0.0, 0.0])
    h.add_edge(0, 1, [0.0, 0.0], 0.0, np.eye(3), loss="cauchy", loss_scale=2.0)
    assert h.cost() == pytest.approx(4.0 * math.log(1 + s / 4.0), rel=1e-15)
    assert h.edges["loss"] == [("cauchy", 2.0)]


# ---- SE(3) -----------------------------------------------------------------

def se3_graph(n=30):
    taus = np.c_[np.tile([1.0, 0.0, 0.1], (n - 1, 1)), np.tile([0.0, 0.05, 0.2], (n - 1, 1))]
    steps = pf.SE3.exp(taus)
    truth = [np.eye(4)]
    for k in range(n - 1):
        truth.append(truth[-1] @ steps[k])
    truth = np.array(truth)
    edges = [(k, k + 1) for k in range(n - 1)] + [(k, k + 10) for k in range(0, n - 10, 4)]
    meas = np.array([pf.SE3.plus(np.linalg.inv(truth[i]) @ truth[j], RNG.normal(0, 0.01, 6)) for i, j in edges])
    start = [np.eye(4)]
    for k in range(n - 1):
        start.append(start[-1] @ meas[k])
    info = np.diag([100.0, 100.0, 100.0, 4000.0, 4000.0, 4000.0])
    return np.array(start), edges, meas, info


def se3_chi2(poses, edges, meas, info):
    total = 0.0
    for (i, j), Z in zip(edges, meas):
        E = np.linalg.inv(Z) @ np.linalg.inv(poses[i]) @ poses[j]
        q = pf.SO3.to_quaternion(pf.SO3.normalize(E[:3, :3]))  # w >= 0
        e = np.r_[E[:3, 3], q[1:]]
        total += e @ info @ e
    return total


def write_se3_g2o(path, poses, edges, meas, info):
    with open(path, "w") as f:
        for k, T in enumerate(poses):
            q = pf.SO3.to_quaternion(T[:3, :3], order="xyzw")
            f.write("VERTEX_SE3:QUAT %d %s\n" % (k, " ".join(repr(v) for v in np.r_[T[:3, 3], q])))
        for (i, j), Z in zip(edges, meas):
            q = pf.SO3.to_quaternion(Z[:3, :3], order="xyzw")
            u = [info[r, c] for r in range(6) for c in range(r, 6)]
            f.write("EDGE_SE3:QUAT %d %d %s %s\n" % (i, j, " ".join(repr(v) for v in np.r_[Z[:3, 3], q]),
                                                      " ".join(repr(v) for v in u)))


def test_se3_graph_cost_and_optimisation_equal_the_cpp_program(tmp_path):
    poses, edges, meas, info = se3_graph()
    g = pf.PoseGraphSE3()
    g.add_nodes(np.arange(len(poses)), poses)
    g.add_edges([e[0] for e in edges], [e[1] for e in edges], meas, info)
    assert g.cost() == pytest.approx(se3_chi2(poses, edges, meas, info), rel=1e-9)
    f = tmp_path / "se3.g2o"
    write_se3_g2o(f, poses, edges, meas, info)
    r = pf.read_g2o(f)
    assert isinstance(r, pf.PoseGraphSE3) and r.num_edges == len(edges)
    assert r.cost() == pytest.approx(g.cost(), rel=1e-9)
    prog = _program("optimize_pose_graph")
    out = tmp_path / "opt.g2o"
    proc = subprocess.run([str(prog), "--input", str(f), "--json", "--out", str(out)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    ref = json.loads(proc.stdout)
    assert r.cost() == ref["file_cost"]
    r.initialize_chordal()
    assert r.cost() == ref["initial_cost"]
    s = r.optimize()
    assert (s.final_cost, s.iterations, s.termination) == (ref["final_cost"], ref["iterations"], ref["termination"])
    back = pf.read_g2o(out)
    np.testing.assert_allclose(r.poses, back.poses, rtol=0, atol=1e-15)  # quaternion text -> matrix
    # write_g2o / read_g2o round trip
    f2 = tmp_path / "again.g2o"
    pf.write_g2o(f2, r)
    again = pf.read_g2o(f2)
    np.testing.assert_allclose(again.poses, r.poses, rtol=0, atol=1e-15)
    assert again.cost() == pytest.approx(r.cost(), rel=1e-9, abs=1e-20)


def test_planar_write_read_round_trip_is_exact(tmp_path):
    poses, edges, meas, info = planar_graph(25)
    g = pf.PoseGraph4Dof()
    g.add_nodes(np.arange(len(poses)), poses, fixed=np.arange(len(poses)) == 3)
    g.add_edges([e[0] for e in edges], [e[1] for e in edges], meas[:, :2], meas[:, 2], info)
    f = tmp_path / "rt.g2o"
    pf.write_g2o(f, g)
    h = pf.read_g2o(f)
    np.testing.assert_array_equal(h.poses, g.poses)
    np.testing.assert_array_equal(h.fixed, g.fixed)
    assert h.cost() == g.cost()
    assert "FIX 3" in f.read_text()


# ---- misuse -----------------------------------------------------------------

def test_bad_input_raises_with_the_cpp_messages(tmp_path):
    g = pf.PoseGraph4Dof()
    g.add_node(0, [0.0, 0.0, 0.0])
    g.add_node(1, [1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="pose graph: duplicate node id 1"):
        g.add_node(1, [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="pose graph: node 7 has a non-finite pose"):
        g.add_node(7, [np.nan, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"pose graph: edge 0 \(0 -> 5\): node 5 does not exist"):
        g.add_edge(0, 5, [1.0, 0.0], 0.0, np.eye(3))
    with pytest.raises(ValueError, match=r"edge 0 \(1 -> 1\): both ends are the same node"):
        g.add_edge(1, 1, [1.0, 0.0], 0.0, np.eye(3))
    with pytest.raises(ValueError, match="the information matrix is not symmetric positive semi-definite"):
        g.add_edge(0, 1, [1.0, 0.0], 0.0, -np.eye(3))
    with pytest.raises(ValueError, match="the measurement is not finite"):
        g.add_edge(0, 1, [np.inf, 0.0], 0.0, np.eye(3))
    with pytest.raises(ValueError, match="the robust-loss scale must be finite and > 0"):
        g.add_edge(0, 1, [1.0, 0.0], 0.0, np.eye(3), loss="huber", loss_scale=-1.0)
    with pytest.raises(ValueError, match="loss must be 'none', 'huber' or 'cauchy'"):
        g.add_edge(0, 1, [1.0, 0.0], 0.0, np.eye(3), loss="tukey")
    with pytest.raises(ValueError, match=r"information: expected an array of shape \(4, 4\) or \(3, 3\)"):
        g.add_edge(0, 1, [1.0, 0.0], 0.0, np.eye(2))
    with pytest.raises(ValueError, match=r"expected an array of shape \(N, 4\) or \(N, 3\)"):
        g.add_nodes([5, 6], np.zeros((2, 5)))
    with pytest.raises(TypeError, match="expected integers"):
        g.add_nodes([5.5, 6.0], np.zeros((2, 3)))
    with pytest.raises(TypeError, match="got None"):
        g.add_node(5, None)
    with pytest.raises(TypeError):
        g.add_node(None, [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="method must be 'lm'"):
        g.optimize(method="dogleg")
    assert g.num_edges == 0
    g.add_node(2, [2.0, 0.0, 0.0])
    g.add_edge(0, 1, [1.0, 0.0], 0.0, np.eye(3))
    with pytest.raises(ValueError, match="not linked"):
        g.optimize()  # node 2 has no edge
    with pytest.raises(ValueError):
        pf.PoseGraph4Dof().optimize()  # empty
    with pytest.raises(ValueError, match="does not exist"):
        g.pose(99)
    with pytest.raises(TypeError, match="PoseGraph4Dof or a PoseGraphSE3"):
        pf.write_g2o(tmp_path / "x.g2o", "not a graph")
    G = pf.PoseGraphSE3()
    T = np.eye(4)
    T[:3, :3] *= 2.0
    with pytest.raises(ValueError, match="SO3: matrix is not orthonormal"):
        G.add_node(0, T)
    with pytest.raises(ValueError, match=r"expected an array of shape \(4, 4\)"):
        G.add_node(0, np.eye(3))


def _small_graphs():
    g = pf.PoseGraph4Dof()
    g.add_nodes([0, 1, 2], [[0.0, 0.0, 0.0], [1.1, 0.1, 0.05], [2.0, -0.1, 0.0]])
    g.add_edges([0, 1], [1, 2], [[1.0, 0.0], [1.0, 0.0]], [0.0, 0.0], np.eye(3))
    G = pf.PoseGraphSE3()
    T = np.tile(np.eye(4), (3, 1, 1))
    T[:, 0, 3] = [0.0, 1.1, 2.0]
    G.add_nodes([0, 1, 2], T)
    Z = np.eye(4)
    Z[0, 3] = 1.0
    G.add_edges([0, 1], [1, 2], np.stack([Z, Z]), np.eye(6))
    return g, G


@pytest.mark.parametrize("option", ["function_tolerance", "gradient_tolerance", "parameter_tolerance",
                                    "initial_lambda"])
@pytest.mark.parametrize("value", [math.nan, -1e-5, math.inf, -math.inf])
def test_optimize_refuses_nan_negative_and_infinite_options_naming_them(option, value):
    for g in _small_graphs():
        before = g.poses.copy()
        with pytest.raises(ValueError, match="PoseGraphOptions: %s must be finite and >= 0, got " % option) as e:
            g.optimize(**{option: value})
        assert str(e.value).endswith({math.nan: "nan", -1e-5: "-1e-05", math.inf: "inf", -math.inf: "-inf"}[value])
        np.testing.assert_array_equal(g.poses, before)  # refused before any work
        for method in ("lm", "gn"):
            with pytest.raises(ValueError, match=option):
                g.optimize(method=method, **{option: value})
    # 0 is allowed (no damping / that test off) and still converges.
    for g in _small_graphs():
        s = g.optimize(initial_lambda=0.0, function_tolerance=0.0)
        assert s.final_cost < 1e-20


def test_optimize_refuses_max_iterations_below_one():
    for g in _small_graphs():
        with pytest.raises(ValueError, match="PoseGraphOptions: max_iterations must be >= 1, got 0"):
            g.optimize(max_iterations=0)
        with pytest.raises(ValueError, match="max_iterations must be >= 1, got -3"):
            g.optimize(max_iterations=-3)


def test_write_g2o_refuses_an_empty_graph_and_what_it_writes_reads_back(tmp_path):
    for empty, tag in ((pf.PoseGraph4Dof(), "VERTEX_SE2"), (pf.PoseGraphSE3(), "VERTEX_SE3:QUAT")):
        f = tmp_path / "empty.g2o"
        with pytest.raises(ValueError, match="the graph has no vertex, and a g2o file needs a %s line" % tag):
            pf.write_g2o(f, empty)
        assert not f.exists()  # nothing written
    # One node and no edge: written, and read back as the same graph.
    g = pf.PoseGraph4Dof()
    g.add_node(4, [1.5, -2.0, 0.25])
    G = pf.PoseGraphSE3()
    T = np.eye(4)
    T[:3, 3] = [1.0, 2.0, 3.0]
    G.add_node(9, T)
    for graph in (g, G):
        f = tmp_path / "one.g2o"
        pf.write_g2o(f, graph)
        back = pf.read_g2o(f)
        assert type(back) is type(graph) and back.num_nodes == 1 and back.num_edges == 0
        np.testing.assert_array_equal(back.ids, graph.ids)
        np.testing.assert_allclose(back.poses, graph.poses, rtol=0, atol=1e-15)


def test_bad_g2o_files_raise_file_errors_with_file_and_line(tmp_path):
    f = tmp_path / "bad.g2o"
    f.write_text("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0\n")
    with pytest.raises(OSError, match=r"bad.g2o:3: "):
        pf.read_g2o(f)
    f.write_text("VERTEX_XYZ 0 0 0 0\n")
    with pytest.raises(pf.FileError, match=r"bad.g2o:1: unsupported g2o tag 'VERTEX_XYZ'"):
        pf.read_g2o(f)
    with pytest.raises(OSError, match="cannot open file for reading"):
        pf.read_g2o(tmp_path / "missing.g2o")


@pytest.mark.parametrize("name", ["input_MITb_g2o.g2o", "manhattanOlson3500.g2o", "parking-garage.g2o"])
def test_public_graphs_equal_the_cpp_program(name, data_dir, tmp_path):
    f = data_dir / "posegraph" / name
    if not f.is_file():
        pytest.skip("%s not found under %s (set POSEFUSE_DATA_DIR)" % (name, f.parent))
    prog = _program("optimize_pose_graph")
    out = tmp_path / "opt.g2o"
    proc = subprocess.run([str(prog), "--input", str(f), "--json", "--out", str(out)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    ref = json.loads(proc.stdout)
    g = pf.read_g2o(f)
    assert (g.num_nodes, g.num_edges) == (ref["nodes"], ref["edges"])
    assert g.cost() == ref["file_cost"]
    if isinstance(g, pf.PoseGraph4Dof):
        g.initialize_rotation_first()
    else:
        g.initialize_chordal()
    assert g.cost() == ref["initial_cost"]
    s = g.optimize()
    assert (s.final_cost, s.iterations, s.termination) == (ref["final_cost"], ref["iterations"], ref["termination"])
    back = pf.read_g2o(out)
    if isinstance(g, pf.PoseGraph4Dof):
        np.testing.assert_array_equal(g.poses, back.poses)
    else:
        np.testing.assert_allclose(g.poses, back.poses, rtol=0, atol=1e-12)
