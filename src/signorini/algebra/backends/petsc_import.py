"""How petsc4py is found and imported (the ``"petsc"`` and ``"petsc-gamg"`` backends, and the
ranks of ``PETSC_COMM_WORLD``), as :mod:`.mkl` finds MKL's runtime library.

:func:`petsc_module` imports ``petsc4py.PETSc`` once, the binary wheel's MPI library first;
nothing else here touches PETSc, so that :mod:`~signorini.algebra.ranks` and the PETSc
backends (:mod:`.petsc`, :mod:`.petsc_rows`, :mod:`.petsc_gamg`) all import it from below.
"""

from __future__ import annotations

import importlib.util
import sys
from functools import cache
from pathlib import Path
from typing import Any

from ..errors import BackendUnavailableError
from .mkl import blas_for_libraries_loaded_later

__all__ = ["INSTALL_HINT", "petsc_library", "petsc_module"]


#: How to install the backend, ending the message of a missing petsc4py.
INSTALL_HINT = (
    "install the extra: pip install 'signorini[mpi]' (binary PETSc + MUMPS + MPICH wheels, "
    "Python >= 3.12), or use a petsc4py built with MUMPS (docs/parallel.md, Install)"
)


@cache
def petsc_module() -> Any:
    """``petsc4py.PETSc``, imported once; :class:`BackendUnavailableError` naming the extra
    when petsc4py is missing or its PETSc has no MUMPS."""
    if "petsc4py.PETSc" not in sys.modules:  # else decided when it was loaded
        _MUMPS_BLAS["mkl"] = _mkl_blas_for_the_wheel()
    try:
        # The binary wheel's package loads its MPI library before petsc4py (it must come
        # first); other installs of petsc4py do not have it.
        import dolfinx_solver  # noqa: F401
    except ImportError:
        pass
    try:
        from petsc4py import PETSc
    except ImportError as err:
        raise BackendUnavailableError(
            f"the petsc backend needs petsc4py, which is not importable ({err}): {INSTALL_HINT}"
        ) from err
    if not PETSc.Sys.hasExternalPackage("mumps"):
        version = ".".join(map(str, PETSc.Sys.getVersion()))
        raise BackendUnavailableError(
            f"the petsc backend needs MUMPS, and this PETSc ({version}) was built without it: "
            f"{INSTALL_HINT}"
        )
    return PETSc


#: Whether MUMPS calls MKL's BLAS instead of the binary wheel's, as :func:`petsc_module`
#: decided before it loaded PETSc.
_MUMPS_BLAS = {"mkl": False}


def _mkl_blas_for_the_wheel() -> bool:
    """Let MUMPS call MKL's BLAS instead of the binary wheel's single-threaded OpenBLAS
    (:func:`.mkl.blas_for_libraries_loaded_later`; docs/parallel.md, *MUMPS's BLAS*): only
    for the wheel of the ``mpi`` extra, whose BLAS is known to be LP64 OpenBLAS
    (``libopenblas.so.0``), and only before its PETSc is loaded. Other PETSc builds keep
    theirs: their BLAS may take 64-bit integers."""
    try:
        spec = importlib.util.find_spec("dolfinx_solver")
    except (ImportError, ValueError, AttributeError):  # e.g. hidden by sys.modules[...] = None
        return False
    if spec is None or not spec.submodule_search_locations:
        return False
    folders = [Path(folder, "lib") for folder in spec.submodule_search_locations]
    if not any((folder / "libopenblas.so.0").is_file() for folder in folders):
        return False
    return blas_for_libraries_loaded_later()


def petsc_library(solver: str = "MUMPS") -> str:
    """``"PETSc 3.25.5 + MUMPS on MKL's BLAS (2 ranks)"``: PETSc's version, the ``solver`` it
    runs (MUMPS's BLAS named where it is MKL's), and ``PETSC_COMM_WORLD``'s size, for a run's
    manifest; what is missing when the backend is not usable."""
    try:
        PETSc = petsc_module()
    except BackendUnavailableError as err:
        return f"PETSc (not usable: {err})"
    version = ".".join(map(str, PETSc.Sys.getVersion()))
    size = PETSc.COMM_WORLD.getSize()
    blas = " on MKL's BLAS" if solver == "MUMPS" and _MUMPS_BLAS["mkl"] else ""
    return f"PETSc {version} + {solver}{blas} ({size} rank{'s' if size > 1 else ''})"
