"""posefuse: trajectory evaluation (evo's definitions), Lie groups, pose graphs,
IMU pre-integration and filters, from Python.

Everything is implemented in the compiled module ``posefuse._posefuse``; this
file re-exports it (plus the optional ``plot`` helper). Importing posefuse
never imports numpy: functions that take or return arrays import it when
first called and raise ImportError with a sentence when it is missing.

    import posefuse
    gt = posefuse.read_trajectory("KITTI_00_gt.txt")      # format auto-detected
    est = posefuse.read_trajectory("KITTI_00_ORB.txt")
    r = posefuse.ape(gt, est, align="se3")                 # evo_ape kitti ... -a
    print(r.rmse, r.mean, r.max, len(r.errors))
    r = posefuse.rpe(gt, est, delta=100, delta_unit="m", all_pairs=True)
"""
from ._posefuse import *  # noqa: F401,F403
from . import _posefuse as _ext

__version__ = _ext.__version__


def plot(result, plane="xy", ax=None):
    """Draws a Result: the reference (dashed) and the aligned estimate
    coloured by its error, in the plane 'xy', 'xz' or 'yz'. Needs matplotlib
    (Debian: python3-matplotlib), imported only here; returns the Axes.
    For an RPE the colour of a pose is the error of the pair ending there."""
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:  # pragma: no cover - depends on the machine
        raise ImportError("posefuse.plot needs matplotlib (Debian: apt install python3-matplotlib)") from e
    import numpy as np

    axes = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}
    if plane not in axes:
        raise ValueError("plane must be 'xy', 'xz' or 'yz', got %r" % (plane,))
    i, j = axes[plane]
    ref = result.ref.positions
    est = result.est_aligned.positions
    err = np.full(len(est), np.nan)
    if result.pairs is None:
        err[:] = result.errors
    else:
        err[result.pairs[:, 1]] = result.errors
    if ax is None:
        ax = plt.figure().add_subplot()
    ax.plot(ref[:, i], ref[:, j], "k--", label="reference")
    sc = ax.scatter(est[:, i], est[:, j], c=err, s=4, cmap="viridis", label="estimate")
    ax.figure.colorbar(sc, ax=ax, label="%s (%s)" % (result.metric.upper(), result.unit))
    ax.set_xlabel(plane[0] + " (m)")
    ax.set_ylabel(plane[1] + " (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend()
    return ax


__all__ = [name for name in dir(_ext) if not name.startswith("_")] + ["plot"]
