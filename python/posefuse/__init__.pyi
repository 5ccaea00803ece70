# Type stubs of the package posefuse: everything of the compiled module
# posefuse._posefuse (_posefuse.pyi), plus the pure-Python plot helper.
from typing import Any, Literal

from ._posefuse import *  # noqa: F401,F403
from ._posefuse import Result, __version__ as __version__

def plot(result: Result, plane: Literal["xy", "xz", "yz"] = "xy", ax: Any = None) -> Any: ...
