"""Work beside the caller's: one background thread for MKL's calls that release the
interpreter (``ctypes``), so that they take the second core while the caller goes on.

The METIS ordering of a mesh's unknowns runs there while the stiffness matrix is assembled
(:class:`~signorini.contact.ordering.Ordering`), and PARDISO's symbolic analysis while the
matrix is rotated into frames and the active set iteration is set up
(:meth:`~.solvers.SPDSolver.analyze`); docs/method.md, *Ordering of the unknowns*.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import TypeVar

from .mkl import mkl_threads_local, openmp_sleep_at_once

__all__ = ["beside"]

T = TypeVar("T")


def _sleep_at_once() -> None:
    openmp_sleep_at_once()


# one worker: the background work of one process runs one piece at a time; its OpenMP
# threads sleep when a call ends instead of waiting 200 ms for more (taking a core meanwhile)
_WORKER = ThreadPoolExecutor(
    max_workers=1, thread_name_prefix="signorini-beside", initializer=_sleep_at_once
)


def beside(work: Callable[..., T], *args: object, one_thread: bool = False) -> Future[T]:
    """``work(*args)`` started in the background thread; its
    :class:`~concurrent.futures.Future` gives the result, or raises its error.

    ``one_thread``: on one MKL thread (:func:`~.mkl.mkl_threads_local`), for work whose
    result does not depend on the number of threads (METIS's ordering does not; PARDISO's
    analysis plans its factorization for the threads it has, so it keeps MKL's own number:
    the factor, and the solution's last bits, are then those of an analysis in the caller's
    thread). A team of two threads of its own waits for work on both cores after its call,
    beside the caller's."""
    return _WORKER.submit(_one_thread, work, *args) if one_thread else _WORKER.submit(work, *args)


def _one_thread(work: Callable[..., T], *args: object) -> T:
    mkl_threads_local(1)
    try:
        return work(*args)
    finally:
        mkl_threads_local(0)
