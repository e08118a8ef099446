"""What a run's manifest records about where it ran: versions, date and host."""

from __future__ import annotations

import datetime
import platform
import socket
import sys

import numpy as np
import scipy

from ..version import __version__

__all__ = ["environment"]


def environment(solver_library: str) -> dict[str, str]:
    """The versions of signorini, Python, NumPy, SciPy and the solver library, the date (UTC,
    ISO 8601) and the host, as a run's manifest records them.

    Parameters
    ----------
    solver_library : str
        The sparse solver library the run uses, with its version
        (:func:`signorini.algebra.backends.selection.solver_library`).
    """
    return {
        "signorini": __version__,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "solver_library": solver_library,
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "host": socket.gethostname(),
        "platform": f"{platform.system()} {platform.machine()}; {sys.implementation.name}",
    }
