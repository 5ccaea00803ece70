"""The synthetic KITTI-like drive shared by the Python tests and
python/bench/bench_eval.py: 10 Hz, speed 8 +- 2 m/s, yaw rate
0.08 sin(0.02 t) + 0.03 sin(0.11 t) rad/s about the camera's y axis (KITTI
camera frame, road plane x-z), 0.3 m height changes; the estimate composes
the ground truth's relative motions with Gaussian noise (2e-4 rad, 1 cm per
step) and sees the world from another frame."""


def rotation(axis_angle):
    """Rotation matrices (N, 3, 3) of rotation vectors (N, 3) (Rodrigues)."""
    import numpy as np

    v = np.atleast_2d(axis_angle)
    theta = np.linalg.norm(v, axis=1)
    k = np.where(theta[:, None] > 0, v / np.where(theta > 0, theta, 1)[:, None], 0.0)
    K = np.zeros((len(v), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = k[:, 2], -k[:, 1], k[:, 0]
    s, c = np.sin(theta)[:, None, None], np.cos(theta)[:, None, None]
    return np.eye(3) + s * K + (1 - c) * (K @ K)


def kitti_like(n, seed=1, dt=0.1):
    """A KITTI-like drive (camera frame: x right, y down, z forward; road
    plane x-z) of n poses at 10 Hz and a drifting, noisy estimate of it.
    Returns (stamps (n,), gt poses (n, 4, 4), est poses (n, 4, 4))."""
    import numpy as np

    rng = np.random.default_rng(seed)
    t = dt * np.arange(n)
    speed = 8.0 + 2.0 * np.sin(0.05 * t)                    # m/s
    yaw_rate = 0.08 * np.sin(0.02 * t) + 0.03 * np.sin(0.11 * t)
    yaw = np.cumsum(yaw_rate) * dt
    gt = np.tile(np.eye(4), (n, 1, 1))
    gt[:, :3, :3] = rotation(np.c_[np.zeros(n), yaw, np.zeros(n)])
    forward = gt[:, :3, 2]
    gt[:, :3, 3] = np.cumsum(forward * (speed * dt)[:, None], axis=0)
    gt[:, 1, 3] += 0.3 * np.sin(0.01 * t)                     # gentle height changes
    # Estimate: per-step relative-motion errors accumulate (drift), seen from
    # another world frame (rotated, shifted).
    est = np.empty_like(gt)
    est[0] = gt[0]
    rel = np.linalg.inv(gt[:-1]) @ gt[1:]
    noise = np.tile(np.eye(4), (n - 1, 1, 1))
    noise[:, :3, :3] = rotation(rng.normal(0, 2e-4, (n - 1, 3)))
    noise[:, :3, 3] = rng.normal(0, 0.01, (n - 1, 3))
    steps = rel @ noise
    for k in range(1, n):
        est[k] = est[k - 1] @ steps[k - 1]
    world = np.eye(4)
    world[:3, :3] = rotation(np.array([[0.02, 0.3, -0.01]]))[0]
    world[:3, 3] = [5.0, -1.0, 2.0]
    return t, gt, world @ est
