"""What a run's manifest records about where it ran: versions, date and host."""

from __future__ import annotations

import ctypes
import datetime
import platform
import socket
import sys

import numpy as np
import scipy

__all__ = ["environment", "solver_library"]


def _mkl_version() -> str | None:
    """MKL's version string (``Intel(R) oneAPI Math Kernel Library Version 2024.2 ...``) if
    its runtime library can be loaded, else None."""
    from ..algebra.mkl import mkl_runtime_candidates

    for candidate in mkl_runtime_candidates():
        try:
            lib = ctypes.CDLL(candidate)
            get = lib.MKL_Get_Version_String
        except (OSError, AttributeError):
            continue
        buf = ctypes.create_string_buffer(256)
        get.argtypes = [ctypes.c_char_p, ctypes.c_int]
        get.restype = None
        get(buf, len(buf))
        return buf.value.decode(errors="replace").strip() or None
    return None


def solver_library(solver: object = None) -> str:
    """The sparse solver library a run uses: MKL PARDISO with MKL's version when the run's
    solver is ``pardiso`` or ``auto`` and MKL loads, else SciPy's SuperLU."""
    name = str(solver) if solver is not None else "auto"
    if name in ("auto", "pardiso"):
        version = _mkl_version()
        if version is not None:
            return f"MKL PARDISO ({version})"
    if name in ("auto", "pardiso", "scipy", "superlu"):
        return f"SuperLU (SciPy {scipy.__version__})"
    return f"{name} (SciPy {scipy.__version__} installed)"


def environment(solver: object = None) -> dict[str, str]:
    """The versions of signorini, Python, NumPy, SciPy and the solver library, the date (UTC,
    ISO 8601) and the host, as a run's manifest records them.

    Parameters
    ----------
    solver : str, optional
        The run's solver by its registry name (``auto``, ``pardiso``, ``scipy``, ...).
    """
    import signorini  # the package is loaded before its modules

    return {
        "signorini": signorini.__version__,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "solver_library": solver_library(solver),
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "host": socket.gethostname(),
        "platform": f"{platform.system()} {platform.machine()}; {sys.implementation.name}",
    }
