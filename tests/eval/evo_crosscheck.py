#!/usr/bin/env python3
"""Independent pure-Python cross-check of posefuse's evo-equivalent metrics.

Plain Python 3, no numpy and no evo; it reads KITTI 06 from the data folder
and runs in under a second. Not part of ctest: its output is what
tests/eval/test_metrics.cpp's KITTI 06 cases require of posefuse (to 1e-5),
and docs/evaluation.md ("Agreement with evo") shows it. It re-derives, from
evo's published definitions, the numbers that those cases check:

  * association: nearest timestamp of the shorter trajectory in the longer
    one (first minimum), kept when |dt| <= 0.01 s;
  * alignment: Horn's closed-form quaternion method (JOSA A 4(4), 1987) for
    the rotation -- a different algorithm from the SVD-based Umeyama used in
    C++, with the same optimum -- and Umeyama's scale tr(R^T Sigma) / sigma_x^2;
  * APE translation, RPE translation / angle (deg) by frames and metres with
    pairs chosen on the aligned estimate, statistics with numpy's population
    std and median.

Usage: python3 tests/eval/evo_crosscheck.py [DATA_DIR]   (default: the data folder beside the checkout)
"""
import math
import os
import sys


def mat_mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(len(b))) for j in range(len(b[0]))]
            for i in range(len(a))]


def transpose(a):
    return [list(r) for r in zip(*a)]


def pose(r, t):
    return (r, list(t))


def compose(p, q):  # p * q
    r = mat_mul(p[0], q[0])
    t = [sum(p[0][i][k] * q[1][k] for k in range(3)) + p[1][i] for i in range(3)]
    return (r, t)


def inverse(p):
    rt = transpose(p[0])
    return (rt, [-sum(rt[i][k] * p[1][k] for k in range(3)) for i in range(3)])


def quat_to_rot(x, y, z, w):
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def rot_angle(r):
    """Angle via a Shepperd-style quaternion, 2 atan2(|v|, |w|) (as scipy)."""
    tr = r[0][0] + r[1][1] + r[2][2]
    cands = [tr, r[0][0], r[1][1], r[2][2]]
    k = max(range(4), key=lambda i: cands[i])
    if k == 0:
        w = math.sqrt(1 + tr) / 2
        v = [(r[2][1] - r[1][2]) / (4 * w), (r[0][2] - r[2][0]) / (4 * w),
             (r[1][0] - r[0][1]) / (4 * w)]
    else:
        i = k - 1
        j, l = (i + 1) % 3, (i + 2) % 3
        vi = math.sqrt(max(0.0, 1 + 2 * r[i][i] - tr)) / 2
        v = [0.0, 0.0, 0.0]
        v[i] = vi
        v[j] = (r[j][i] + r[i][j]) / (4 * vi)
        v[l] = (r[l][i] + r[i][l]) / (4 * vi)
        w = (r[l][j] - r[j][l]) / (4 * vi)
    return 2 * math.atan2(math.sqrt(sum(c * c for c in v)), abs(w))


def read_kitti(path):
    out = []
    for line in open(path):
        if not line.strip():
            continue
        v = [float(s) for s in line.split()]
        out.append(pose([v[0:3], v[4:7], v[8:11]], [v[3], v[7], v[11]]))
    return out


def read_tum(path):
    stamps, poses = [], []
    for line in open(path):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        v = [float(s) for s in line.split()]
        stamps.append(v[0])
        poses.append(pose(quat_to_rot(*v[4:8]), v[1:4]))
    return stamps, poses


def associate(ref_stamps, est_stamps, max_diff=0.01):
    est_longer = len(est_stamps) > len(ref_stamps)
    short, long_ = (ref_stamps, est_stamps) if est_longer else (est_stamps, ref_stamps)
    si, li = [], []
    for i, t in enumerate(short):
        diffs = [abs(s - t) for s in long_]
        j = min(range(len(diffs)), key=lambda k: (diffs[k], k))
        if diffs[j] <= max_diff:
            si.append(i)
            li.append(j)
    return (si, li) if est_longer else (li, si)


def jacobi_eigen(a, sweeps=100):
    """Eigen-decomposition of a symmetric matrix (cyclic Jacobi)."""
    n = len(a)
    a = [row[:] for row in a]
    v = [[float(i == j) for j in range(n)] for i in range(n)]
    for _ in range(sweeps):
        off = sum(a[i][j] ** 2 for i in range(n) for j in range(n) if i != j)
        if off < 1e-30:
            break
        for p in range(n):
            for q in range(p + 1, n):
                if abs(a[p][q]) < 1e-300:
                    continue
                theta = (a[q][q] - a[p][p]) / (2 * a[p][q])
                t = math.copysign(1.0, theta) / (abs(theta) + math.sqrt(theta * theta + 1))
                c = 1 / math.sqrt(t * t + 1)
                s = t * c
                for k in range(n):
                    akp, akq = a[k][p], a[k][q]
                    a[k][p], a[k][q] = c * akp - s * akq, s * akp + c * akq
                for k in range(n):
                    apk, aqk = a[p][k], a[q][k]
                    a[p][k], a[q][k] = c * apk - s * aqk, s * apk + c * aqk
                for k in range(n):
                    vkp, vkq = v[k][p], v[k][q]
                    v[k][p], v[k][q] = c * vkp - s * vkq, s * vkp + c * vkq
    return [a[i][i] for i in range(n)], v


def horn_alignment(x, y, with_scale):
    """Similarity y ~ c R x + t via Horn's quaternion method."""
    n = len(x)
    mx = [sum(p[i] for p in x) / n for i in range(3)]
    my = [sum(p[i] for p in y) / n for i in range(3)]
    # M = sum (x - mx)(y - my)^T, Horn's S matrix
    m = [[sum((x[k][i] - mx[i]) * (y[k][j] - my[j]) for k in range(n)) for j in range(3)]
         for i in range(3)]
    sxx, sxy, sxz = m[0]
    syx, syy, syz = m[1]
    szx, szy, szz = m[2]
    nmat = [[sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
            [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
            [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
            [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz]]
    vals, vecs = jacobi_eigen(nmat)
    k = max(range(4), key=lambda i: vals[i])
    w, qx, qy, qz = (vecs[i][k] for i in range(4))
    r = quat_to_rot(qx, qy, qz, w)
    sigma_x = sum((p[i] - mx[i]) ** 2 for p in x for i in range(3)) / n
    # Umeyama's c = tr(D S) / sigma_x^2 = tr(R^T Sigma_xy) / sigma_x^2, Sigma_xy = M^T / n
    c = (sum(r[i][j] * m[j][i] for i in range(3) for j in range(3)) / n / sigma_x
         if with_scale else 1.0)
    t = [my[i] - c * sum(r[i][j] * mx[j] for j in range(3)) for i in range(3)]
    return r, t, c


def apply_alignment(poses, r, t, c):
    return [compose(pose(r, t), pose(p[0], [c * v for v in p[1]])) for p in poses]


def stats(e):
    n = len(e)
    mean = sum(e) / n
    s = sorted(e)
    med = s[n // 2] if n % 2 else 0.5 * (s[n // 2 - 1] + s[n // 2])
    return dict(count=n, rmse=math.sqrt(sum(v * v for v in e) / n), mean=mean, median=med,
                std=math.sqrt(sum((v - mean) ** 2 for v in e) / n), min=s[0], max=s[-1],
                sse=sum(v * v for v in e))


def ape_trans(ref, est):
    return [math.dist(p[1], q[1]) for p, q in zip(est, ref)]


def pairs_frames(n, d):
    ids = list(range(0, n, d))
    return list(zip(ids, ids[1:]))


def pairs_path(poses, d):
    ids, path = [], 0.0
    for k in range(len(poses)):
        if k:
            path += math.dist(poses[k][1], poses[k - 1][1])
        if path >= d:
            ids.append(k)
            path = 0.0
    return list(zip(ids, ids[1:]))


def rpe(ref, est, pairs, angle):
    out = []
    for i, j in pairs:
        e = compose(inverse(compose(inverse(ref[i]), ref[j])), compose(inverse(est[i]), est[j]))
        out.append(rot_angle(e[0]) * 180 / math.pi if angle else math.hypot(*e[1]))
    return out


def show(name, s, scale=None):
    extra = "" if scale is None else f" scale={scale:.6f}"
    print(f"{name:30s} " + " ".join(f"{k}={v:.6f}" if k != "count" else f"n={v}"
                                      for k, v in s.items()) + extra)


def main():
    data = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(__file__), "..", "..", "..", "shared", "data")
    d = os.path.join(data, "kitti", "06")
    gt = read_kitti(os.path.join(d, "groundtruth.txt"))
    st = read_kitti(os.path.join(d, "orbslam2_stereo.txt"))
    times = [float(l) for l in open(os.path.join(d, "times.txt")) if l.strip()]

    xs, ys = [p[1] for p in st], [p[1] for p in gt]
    r, t, c = horn_alignment(xs, ys, False)
    st_se3 = apply_alignment(st, r, t, c)
    show("ape stereo se3", stats(ape_trans(gt, st_se3)))
    r3, t3, c3 = horn_alignment(xs, ys, True)
    show("ape stereo sim3", stats(ape_trans(gt, apply_alignment(st, r3, t3, c3))), c3)
    show("rpe stereo 1f", stats(rpe(gt, st, pairs_frames(len(gt), 1), False)))
    show("rpe stereo 1f deg", stats(rpe(gt, st, pairs_frames(len(gt), 1), True)))
    show("rpe stereo 10f", stats(rpe(gt, st, pairs_frames(len(gt), 10), False)))
    show("rpe stereo 100m", stats(rpe(gt, st_se3, pairs_path(st_se3, 100.0), False)))
    show("rpe stereo 100m deg", stats(rpe(gt, st_se3, pairs_path(st_se3, 100.0), True)))

    mono_stamps, mono = read_tum(os.path.join(d, "orbslam2_mono.tum"))
    ri, ei = associate(times, mono_stamps)
    ref_m, est_m = [gt[i] for i in ri], [mono[i] for i in ei]
    rm, tm, cm = horn_alignment([p[1] for p in est_m], [p[1] for p in ref_m], True)
    mono_sim3 = apply_alignment(est_m, rm, tm, cm)
    print("associated mono pairs:", len(ri))
    show("ape mono sim3", stats(ape_trans(ref_m, mono_sim3)), cm)
    show("rpe mono 100m sim3", stats(rpe(ref_m, mono_sim3, pairs_path(mono_sim3, 100.0), False)),
         cm)


if __name__ == "__main__":
    main()
