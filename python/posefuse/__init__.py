"""posefuse: trajectory evaluation (evo's definitions), Lie groups, pose graphs,
IMU pre-integration and filters, from Python.

Everything is implemented in the compiled module ``posefuse._posefuse``; this
file re-exports it. Importing posefuse never imports numpy: functions that take
or return arrays import it when first called.
"""
from ._posefuse import *  # noqa: F401,F403
from . import _posefuse as _ext

__all__ = [name for name in dir(_ext) if not name.startswith("_")]
__version__ = getattr(_ext, "__version__", "0.1.0")
