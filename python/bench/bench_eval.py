#!/usr/bin/env python3
"""APE (SE(3) alignment) and RPE (100 m, all pairs) of a 20,000-pose
KITTI-like trajectory from Python: posefuse against evo's Python API when
evo is importable, otherwise against the numpy re-implementation below of
the same definitions.

    PYTHONPATH=build /usr/bin/python3 python/bench/bench_eval.py [--poses 20000] [--repeat 5]

The trajectory (generator `kitti_like`, python/tests/drives.py): 10 Hz, speed 8 +- 2 m/s,
yaw rate 0.08 sin(0.02 t) + 0.03 sin(0.11 t) rad/s about the camera's y axis
(KITTI camera frame, road plane x-z), 0.3 m height changes; the estimate
composes the ground truth's relative motions with Gaussian noise
(2e-4 rad, 1 cm per step, seed 1) and sees the world from another frame.
Both are written as KITTI files (frame by frame, as `evo_ape kitti`) and
read back; only the evaluation is timed, from trajectories in memory, as
the best of --repeat runs. Before timing, the two implementations' rmse,
mean, median, std, min, max and sse are checked equal (relative 1e-9).

The numpy reference follows evo (evo/core/geometry.py, trajectory.py,
filters.py, metrics.py): Umeyama alignment and the errors vectorised as
numpy does naturally; the all-pairs search by path length is evo's own
loop (for each start pose, argmin of |accumulated distance - delta| over
the poses after it, kept within delta * tol), the relative-pose errors of
the pairs vectorised.
"""
import argparse
import os
import sys
import tempfile
import time

import numpy as np

import posefuse

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from drives import kitti_like  # noqa: E402  (the tests' generator)


# ---- numpy reference (evo's definitions) -----------------------------------

def statistics(e):
    return {"rmse": float(np.sqrt(np.mean(e ** 2))), "mean": float(np.mean(e)), "median": float(np.median(e)),
            "std": float(np.std(e)), "min": float(np.min(e)), "max": float(np.max(e)), "sse": float(np.sum(e ** 2))}


def umeyama(x, y):
    """evo's geometry.umeyama_alignment(x, y) without scale; x, y (3, N)."""
    m = x.shape[1]
    mean_x, mean_y = x.mean(axis=1), y.mean(axis=1)
    cov_xy = (y - mean_y[:, None]) @ (x - mean_x[:, None]).T / m
    u, d, v = np.linalg.svd(cov_xy)
    s = np.eye(3)
    if np.linalg.det(u) * np.linalg.det(v) < 0.0:
        s[2, 2] = -1
    r = u @ s @ v
    return r, mean_y - r @ mean_x


def numpy_ape_se3(gt, est):
    r, t = umeyama(est[:, :3, 3].T, gt[:, :3, 3].T)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = r, t
    aligned = T @ est
    return statistics(np.linalg.norm(aligned[:, :3, 3] - gt[:, :3, 3], axis=1))


def se3_inverse(T):
    inv = np.tile(np.eye(4), (len(T), 1, 1))
    rt = np.transpose(T[:, :3, :3], (0, 2, 1))
    inv[:, :3, :3] = rt
    inv[:, :3, 3] = -np.einsum("nij,nj->ni", rt, T[:, :3, 3])
    return inv


def numpy_rpe_path_all_pairs(gt, est, delta=100.0, tol=0.1):
    # evo filters.filter_pairs_by_path(..., all_pairs=True) on the estimate.
    positions = est[:, :3, 3]
    distances = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(positions, axis=0), axis=1))))
    pairs = []
    for i in range(len(positions) - 1):
        offset = i + 1
        from_here = distances[offset:] - distances[i]
        candidate = int(np.argmin(np.abs(from_here - delta)))
        if np.abs(from_here[candidate] - delta) > tol * delta:
            continue
        pairs.append((i, candidate + offset))
    if not pairs:
        raise ValueError("empty index list")
    i, j = np.array(pairs).T
    q_rel = se3_inverse(gt[i]) @ gt[j]
    p_rel = se3_inverse(est[i]) @ est[j]
    e = se3_inverse(q_rel) @ p_rel
    return statistics(np.linalg.norm(e[:, :3, 3], axis=1))


# ---- evo's Python API, when importable ------------------------------------

def evo_functions():
    try:
        from evo.core import metrics, trajectory
    except ImportError:
        return None

    def ape(gt, est):
        ref, e = trajectory.PosePath3D(poses_se3=list(gt)), trajectory.PosePath3D(poses_se3=list(est))
        e.align(ref, correct_scale=False)
        m = metrics.APE(metrics.PoseRelation.translation_part)
        m.process_data((ref, e))
        return m.get_all_statistics()

    def rpe(gt, est):
        ref, e = trajectory.PosePath3D(poses_se3=list(gt)), trajectory.PosePath3D(poses_se3=list(est))
        m = metrics.RPE(metrics.PoseRelation.translation_part, 100.0, metrics.Unit.meters, 0.1, True)
        m.process_data((ref, e))
        return m.get_all_statistics()

    return ape, rpe


def best_time(fn, repeat):
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def check_equal(a, b, what):
    for key in ("rmse", "mean", "median", "std", "min", "max", "sse"):
        if not np.isclose(a[key], b[key], rtol=1e-9, atol=0.0):
            sys.exit("%s: %s differs: posefuse %r, reference %r" % (what, key, a[key], b[key]))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--poses", type=int, default=20000)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    _, gt, est = kitti_like(args.poses)
    with tempfile.TemporaryDirectory() as d:
        posefuse.write_trajectory(os.path.join(d, "gt.txt"), posefuse.Trajectory(np.arange(args.poses), gt), "kitti")
        posefuse.write_trajectory(os.path.join(d, "est.txt"), posefuse.Trajectory(np.arange(args.poses), est), "kitti")
        g = posefuse.read_trajectory(os.path.join(d, "gt.txt"))
        e = posefuse.read_trajectory(os.path.join(d, "est.txt"))
    gt_np, est_np = np.array(g.poses), np.array(e.poses)  # the values as read back, for both sides

    def pf_ape():
        return posefuse.ape(g, e, align="se3").statistics

    def pf_rpe():
        return posefuse.rpe(g, e, delta=100, delta_unit="m", all_pairs=True).statistics

    evo = evo_functions()
    if evo is not None:
        name = "evo %s Python API" % __import__("evo").__version__
        ref_ape, ref_rpe = (lambda: evo[0](gt_np, est_np)), (lambda: evo[1](gt_np, est_np))
    else:
        name = "numpy %s re-implementation (evo not importable)" % np.__version__
        ref_ape, ref_rpe = (lambda: numpy_ape_se3(gt_np, est_np)), (lambda: numpy_rpe_path_all_pairs(gt_np, est_np))
    check_equal(pf_ape(), ref_ape(), "APE")
    check_equal(pf_rpe(), ref_rpe(), "RPE")
    rows = []
    for what, pf, ref in (("APE SE(3)", pf_ape, ref_ape), ("RPE 100 m all pairs", pf_rpe, ref_rpe)):
        t_pf, t_ref = best_time(pf, args.repeat), best_time(ref, args.repeat)
        rows.append((what, t_pf, t_ref))
    total_pf, total_ref = sum(r[1] for r in rows), sum(r[2] for r in rows)
    print("%d poses, best of %d; reference: %s" % (args.poses, args.repeat, name))
    print("%-22s %12s %12s %8s" % ("", "posefuse ms", "reference ms", "ratio"))
    for what, t_pf, t_ref in rows + [("both", total_pf, total_ref)]:
        print("%-22s %12.2f %12.2f %7.1fx" % (what, 1e3 * t_pf, 1e3 * t_ref, t_ref / t_pf))


if __name__ == "__main__":
    main()
