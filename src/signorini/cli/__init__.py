"""Command line: ``signorini run example-6.2 --out results/6.2``.

``run`` takes one of the paper's examples by name, or a Python file of your own that defines
``problem()`` returning a :class:`~signorini.problem.ContactProblem` (see
``examples/inclined_block.py``), and optionally ``load_path()`` returning the load steps
solved before it. A problem file is Python code: it runs with the rights of the user who
runs the command, like any script; signorini never executes a file that a results folder
names (``--resume`` and ``figures`` take the problem from the command line).

A run owns its output folder (:mod:`signorini.output.run`): it refuses a non-empty folder
unless ``--overwrite`` is given, locks it while it writes, and records its files, settings
and environment in ``signorini-run.json``. Each level's VTU file, history row and resume
state are written (atomically) as soon as the level is done, so an interrupted run keeps
what it finished and ``--resume`` continues it, after checking that the problem named is the
one that produced its levels (:mod:`.identity`); the figures follow at the end. A run that
fails (a solver's error in a level, an unreadable file) records ``failed`` and the error in
its manifest, draws the figures of the levels it finished and exits with status 2. Ctrl-C stops
a run with one line saying what finished and where (exit status 130), SIGTERM likewise (exit
status 143); a closed stdout (``| head``) only stops the progress lines.

=============  ===========================================================================
``parser``     the arguments, and which flag sets which field of ``AdaptiveOptions``
``settings``   a run's settings from the flags, or from the manifest with ``--resume``
``problems``   a built-in example by name, or ``problem()`` and ``load_path()`` from a file
``identity``   whether a folder's levels come from the problem named (rebuilt data)
``levels``     each level's files as soon as it is done; progress and interruption lines
``figures``    a run's figures; the uniform refinement it is compared with
``run``        ``signorini run`` as named steps
=============  ===========================================================================
"""

from __future__ import annotations

import logging
import signal
import sys
import threading

from ..runtime import retain_freed_memory
from . import figures, run
from .levels import Printer, Status
from .parser import parser
from .problems import ProblemFileError, load_problem
from .ranks import end_ranks

__all__ = ["EXIT_TERMINATED", "load_problem", "main"]

#: exit status of a run stopped by SIGTERM (128 + 15, as a shell reports it)
EXIT_TERMINATED = 143


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the run is, so that it ends as Ctrl-C does."""


def _terminate(signum, frame) -> None:
    raise Terminated


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``signorini`` command.

    Returns the exit status: 0 on success, 2 for an error (one message on stderr; for a
    problem file that raises, the traceback of its own frames), 130 when interrupted
    (Ctrl-C) and 143 when terminated (SIGTERM), with one line saying what finished and
    where. Under ``mpiexec`` with the ``petsc`` backend a failed or interrupted rank ends
    the whole job (:func:`.ranks.end_ranks`).
    """
    return end_ranks(_main(argv))


def _main(argv: list[str] | None) -> int:
    """:func:`main` on this process."""
    args = parser().parse_args(argv)
    retain_freed_memory()  # large meshes: reuse freed pages instead of faulting in new ones
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    verbose = getattr(args, "verbose", False)
    logging.getLogger("signorini").setLevel(logging.INFO if verbose else logging.NOTSET)
    status = Status(say=Printer(quiet=getattr(args, "quiet", False)))
    main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _terminate) if main_thread else None
    try:
        if args.command == "run":
            return run.run(args, status)
        if args.command == "figures":
            written = figures.figures_command(args.example, args.out, status)
            status.say("\n".join(str(p) for p in written))
            return 0
    except KeyboardInterrupt as exc:
        terminated = isinstance(exc, Terminated)
        if status.folder is not None and args.command == "run":
            try:
                status.folder.set_status("interrupted")
            except OSError:
                pass
        how = "terminated (SIGTERM)" if terminated else "interrupted"
        line = status.interrupted(how) if args.command == "run" else f"signorini: {how}"
        print(line, file=sys.stderr, flush=True)
        return EXIT_TERMINATED if terminated else 130
    except ProblemFileError as exc:
        print(f"signorini: error: {exc}", file=sys.stderr)
        return 2
    except (ValueError, RuntimeError, OSError) as exc:
        print(f"signorini: error: {exc}", file=sys.stderr)
        return 2
    finally:
        if main_thread:
            signal.signal(signal.SIGTERM, previous)
        if status.folder is not None:
            status.folder.close()
    return 1
