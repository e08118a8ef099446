"""MKL's runtime library, found through public routes only, and its ``pardiso`` symbol.

MKL's single dynamic library ``mkl_rt`` is looked for in this order: the files of the
installed ``mkl`` distribution (``importlib.metadata``; the ``fast`` extra installs it with
``pypardiso``), the ``lib`` folder of the Python prefix (conda), and
:func:`ctypes.util.find_library`. :mod:`.pardiso` calls what :func:`pardiso_function` loads.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import importlib.metadata
import re
import sys
from collections.abc import Callable
from functools import cache, lru_cache
from pathlib import Path

from ..errors import BackendUnavailableError

__all__ = [
    "blas_for_libraries_loaded_later",
    "mkl_runtime_candidates",
    "mkl_threads_local",
    "mkl_version",
    "openmp_sleep_at_once",
    "pardiso_function",
]

#: ``MKL_Set_Interface_Layer``'s LP64: 32-bit integers (``mkl_service.h``).
_MKL_INTERFACE_LP64 = 0

#: File names of MKL's single dynamic library on Linux, macOS and Windows.
_MKL_RT = re.compile(r"(lib)?mkl_rt(\.\d+)*\.(so(\.\d+)*|dylib|dll)")


def mkl_runtime_candidates() -> list[str]:
    """Paths (or a loader name) of MKL's single dynamic library ``mkl_rt``, best first.

    Returns
    -------
    list of str
        From the installed ``mkl`` distribution's file list, then the Python prefix's ``lib``
        (``Library/bin`` on Windows) folder, then the system loader's search; may be empty.
    """
    candidates: list[str] = []
    try:
        dist = importlib.metadata.distribution("mkl")
    except importlib.metadata.PackageNotFoundError:
        dist = None
    if dist is not None:
        files = [f for f in dist.files or () if _MKL_RT.fullmatch(Path(f).name)]
        candidates += [str(Path(dist.locate_file(f)).resolve()) for f in files]
    for folder in (Path(sys.prefix, "lib"), Path(sys.prefix, "Library", "bin")):
        if folder.is_dir():
            candidates += [str(p) for p in sorted(folder.iterdir()) if _MKL_RT.fullmatch(p.name)]
    found = ctypes.util.find_library("mkl_rt")
    if found:
        candidates.append(found)
    return list(dict.fromkeys(candidates))  # without repetitions, order kept


@lru_cache(maxsize=1)
def pardiso_function() -> Callable[..., None]:
    """The ``pardiso`` symbol of MKL's runtime library, with its argument types.

    Returns
    -------
    callable
        The C function ``pardiso`` (64-bit handle ``pt``, 32-bit integers).

    Raises
    ------
    BackendUnavailableError
        If no candidate of :func:`mkl_runtime_candidates` loads and exports ``pardiso``; the
        message lists what was tried.
    """
    tried = []
    for path in mkl_runtime_candidates():
        try:
            func = ctypes.CDLL(path).pardiso
        except (OSError, AttributeError) as err:  # not loadable, or no pardiso symbol
            tried.append(f"{path}: {err}")
            continue
        i32p = ctypes.POINTER(ctypes.c_int32)
        func.argtypes = [
            ctypes.POINTER(ctypes.c_int64),  # pt: internal handle, 64 pointers
            i32p,  # maxfct
            i32p,  # mnum
            i32p,  # mtype
            i32p,  # phase
            i32p,  # n
            ctypes.c_void_p,  # a
            i32p,  # ia
            i32p,  # ja
            i32p,  # perm
            i32p,  # nrhs
            i32p,  # iparm
            i32p,  # msglvl
            ctypes.c_void_p,  # b
            ctypes.c_void_p,  # x
            i32p,  # error
        ]
        func.restype = None
        return func
    detail = "; ".join(tried) if tried else "no file found"
    raise BackendUnavailableError(
        f"MKL's runtime library mkl_rt could not be loaded ({detail}); install it with "
        "`pip install signorini[fast]` (or `pip install mkl`)"
    )


def mkl_threads_local(n: int) -> int:
    """Set the number of threads MKL uses in the calling thread (``mkl_set_num_threads_local``;
    0 returns to the global setting); the previous local setting is returned (0 where MKL has
    no such call).

    Raises
    ------
    BackendUnavailableError
        If MKL cannot be loaded.
    """
    func = _mkl_call("MKL_Set_Num_Threads_Local")
    return 0 if func is None else int(func(int(n)))


def openmp_sleep_at_once() -> bool:
    """Let the OpenMP threads of the calling thread's team sleep as soon as a parallel region
    ends (Intel OpenMP's ``kmp_set_blocktime(0)``; they wait 200 ms by default), so that
    after a call of MKL in a thread of ours they do not take a core from the main thread's
    work. False where the OpenMP runtime MKL loaded has no such call.

    Raises
    ------
    BackendUnavailableError
        If MKL cannot be loaded.
    """
    threads = _mkl_call("MKL_Get_Max_Threads")  # loads MKL's threading layer and its OpenMP
    if threads is not None:
        threads()
    try:
        func = ctypes.CDLL(None).kmp_set_blocktime
    except (OSError, AttributeError):
        return False
    func.argtypes = [ctypes.c_int]
    func.restype = None
    func(0)
    return True


@cache
def blas_for_libraries_loaded_later() -> bool:
    """Make MKL's BLAS and LAPACK the ones that the shared libraries loaded from now on call,
    where they leave the BLAS symbols (``dgemm_``, …) to the dynamic linker.

    MKL's runtime library is loaded into the global symbol scope (``RTLD_GLOBAL``), which the
    dynamic linker searches before a library's own dependencies: a library loaded later that
    calls ``dgemm_`` binds to MKL's, not to the BLAS it was linked with. :mod:`.petsc` calls
    this before it imports petsc4py, for MUMPS's factorization (docs/parallel.md, *MUMPS's
    BLAS*).

    Returns
    -------
    bool
        True if MKL is loaded globally with 32-bit BLAS integers (LP64, the interface of the
        BLAS it replaces); False, with nothing changed, where MKL cannot be loaded or its
        interface layer is already the 64-bit one.
    """
    for path in mkl_runtime_candidates():
        try:
            lib = ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
            layer = lib.MKL_Set_Interface_Layer
        except (OSError, AttributeError):
            continue
        layer.argtypes = [ctypes.c_int]
        layer.restype = ctypes.c_int
        return layer(_MKL_INTERFACE_LP64) == _MKL_INTERFACE_LP64
    return False


@cache
def _mkl_call(name: str) -> Callable[..., int] | None:
    """MKL's service function ``name`` (one int argument or none, an int result), or None if
    its library does not export it."""
    pardiso_function()  # loads MKL, or says why not
    for path in mkl_runtime_candidates():
        try:
            func = getattr(ctypes.CDLL(path), name)
        except (OSError, AttributeError):
            continue
        func.restype = ctypes.c_int
        return func
    return None


def mkl_version() -> str | None:
    """MKL's version string (``Intel(R) oneAPI Math Kernel Library Version 2024.2 ...``) if
    its runtime library can be loaded, else None."""
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
