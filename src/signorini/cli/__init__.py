"""Command line: ``signorini run example-6.2 --out results/6.2``.

``run`` takes one of the paper's examples by name, or a Python file of your own that defines
``problem()`` returning a :class:`~signorini.problem.ContactProblem` (see
``examples/inclined_block.py``). A problem file is Python code: it runs with the rights of
the user who runs the command, like any script.

A run owns its output folder (:mod:`signorini.output.run`): it refuses a non-empty folder
unless ``--overwrite`` is given, and records its files and settings in
``signorini-run.json``. Each level's VTU file, history row and resume state are written
(atomically) as soon as the level is done, so an interrupted run keeps what it finished and
``--resume`` continues it; the figures follow at the end. Ctrl-C stops a run with one line
saying what finished and where (exit status 130).

=============  ===========================================================================
``parser``     the arguments, and which flag sets which field of ``AdaptiveOptions``
``settings``   a run's settings from the flags, or from the manifest with ``--resume``
``problems``   a built-in example by name or ``problem()`` from a file
``levels``     each level's files as soon as it is done; progress and interruption lines
``figures``    a run's figures; the uniform refinement it is compared with
``run``        ``signorini run`` as named steps
=============  ===========================================================================
"""

from __future__ import annotations

import logging
import sys

from ..runtime import retain_freed_memory
from . import figures, run
from .levels import Status
from .parser import parser
from .problems import ProblemFileError, label, load_problem

__all__ = ["load_problem", "main"]


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``signorini`` command.

    Returns the exit status: 0 on success, 2 for an error (one message on stderr; for a
    problem file that raises, the traceback of its own frames), 130 when interrupted
    (Ctrl-C), with one line saying what finished and where.
    """
    args = parser().parse_args(argv)
    retain_freed_memory()  # large meshes: reuse freed pages instead of faulting in new ones
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    status = Status()
    try:
        if args.command == "run":
            return run.run(args, status)
        if args.command == "figures":
            written = figures.figures(label(args.example), args.out)
            print("\n".join(str(p) for p in written))
            return 0
    except KeyboardInterrupt:
        if status.folder is not None:
            try:
                status.folder.set_status("interrupted")
            except OSError:
                pass
        print(status.interrupted(), file=sys.stderr, flush=True)
        return 130
    except ProblemFileError as exc:
        print(f"signorini: error: {exc}", file=sys.stderr)
        return 2
    except (ValueError, RuntimeError, OSError) as exc:
        print(f"signorini: error: {exc}", file=sys.stderr)
        return 2
    return 1
