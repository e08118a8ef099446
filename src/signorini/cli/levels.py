"""Each level of a run written as soon as it is done, its progress line with the time left,
where a run is when it is interrupted, and progress output that survives a closed pipe."""

from __future__ import annotations

import math
import os
import shlex
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np

from ..loop import AdaptiveOptions, Level, roundoff_text
from ..loop.record import ElasticityRecord
from ..output import HistoryWriter, write_vtu
from ..output.run import RunFolder
from ..output.vtu import write_pvd

__all__ = ["Clock", "Printer", "Status", "progress", "write_levels"]

#: the time left is shown once a run has taken this many seconds
LONG_RUN_SECONDS = 10.0


#: The errors a level's line shows without an estimator: (shown as, column, its rate's column).
ERRORS_SHOWN = (
    ("error", "error_energy", "rate_energy"),
    ("h1", "error_h1", "rate_h1"),
    ("l2", "error_l2", "rate_l2"),
)


def progress(level: Level) -> str:
    """The progress line of a finished level (:func:`elasticity_progress` for a 3D level
    without contact)."""
    r = level.record
    if isinstance(r, ElasticityRecord):
        return elasticity_progress(r)
    line = f"level {r.level:3d}  ndof {r.ndof:9d}  cells {r.n_cells:8d}"
    if not np.isnan(r.eta):
        line += f"  eta {r.eta:.4e}"
    if not np.isnan(r.error_energy):
        line += f"  error {r.error_energy:.4e}  eff {r.efficiency:.3f}"
    line += (
        f"  pdas {r.pdas_iterations:2d}  active {r.n_active:5d}"
        f"  [{r.t_assemble + r.t_solve + r.t_estimate + r.t_mark + r.t_refine:.2f}s]"
    )
    return line


def elasticity_progress(r: ElasticityRecord) -> str:
    """The progress line of a level without contact (3D): its unknowns and cells, η_h and
    the efficiency index where known, the errors it knows with their observed rates (the history's
    ``rate_*`` columns, when the problem measures them), the solver and, if iterative, its
    iterations, the seconds of its steps."""
    row = {"error_energy": r.error_energy, "error_h1": r.error_h1, **r.extra}
    line = f"level {r.level:3d}  ndof {r.ndof:9d}  cells {r.n_cells:8d}"
    if math.isfinite(r.eta):
        line += f"  eta {r.eta:.4e}"
        if math.isfinite(r.efficiency):
            line += f"  eff {r.efficiency:.3f}"
    for shown, column, rate in ERRORS_SHOWN:
        value = float(row.get(column, math.nan))
        if math.isfinite(value):
            line += f"  {shown} {value:.4e}"
            if math.isfinite(float(row.get(rate, math.nan))):
                line += f" ({float(row[rate]):+.2f})"
    line += f"  {r.backend}"
    if "linear_iterations" in r.extra:
        line += f" {r.extra['linear_iterations']} its"
    return line + f"  [{r.t_assemble + r.t_solve + r.t_estimate + r.t_mark + r.t_refine:.2f}s]"


class Clock:
    """The wall-clock time of each level and an estimate of the time left.

    The estimate assumes what the loop's levels show: the time of a level is proportional
    to its number of unknowns (the last level's seconds per unknown, files included), and
    each level has ``r`` times the unknowns of the one before (``r`` measured on the last
    two levels). The levels still to come are those of ``ndof_k r^j ≤ max_ndof`` within
    ``max_levels``; their predicted times are summed. A run that stops on ``tol`` may end
    sooner. Shown only on runs longer than :data:`LONG_RUN_SECONDS`.
    """

    def __init__(self, options: AdaptiveOptions) -> None:
        self.options = options
        self.start = self.last = time.perf_counter()
        self.ndof: list[int] = []

    def lap(self, level: Level) -> str:
        """The suffix of ``level``'s progress line: its wall time, and on a long run the
        time so far and the estimated time left."""
        now = time.perf_counter()
        seconds, self.last = now - self.last, now
        r = level.record
        self.ndof.append(int(r.ndof))
        text = f"  wall {seconds:.1f}s"
        elapsed = now - self.start
        if elapsed < LONG_RUN_SECONDS or len(self.ndof) < 2 or r.ndof <= 0:
            return text
        left = self.left(r.level, seconds / r.ndof)
        if left is not None:
            text += f"  total {elapsed:.0f}s, about {left:.0f}s left"
        return text

    def left(self, level: int, per_dof: float) -> float | None:
        """Seconds the remaining levels take, estimated; None without a growth to go by."""
        growth = self.ndof[-1] / max(self.ndof[-2], 1)
        if not growth > 1.01:
            return None
        ndof, total, k = float(self.ndof[-1]), 0.0, level
        budget = float(self.options.max_ndof)
        while k + 1 < self.options.max_levels:
            ndof *= growth
            if ndof > budget or not math.isfinite(ndof):
                break
            total += per_dof * ndof
            k += 1
        return total


class Printer:
    """Progress output on stdout that stops, and lets the run go on, when stdout is closed
    (``signorini run ... | head -2``): the first failed write redirects stdout to the null
    device (so the interpreter's last flush does not fail either) and later lines are
    dropped."""

    def __init__(self, quiet: bool = False) -> None:
        self.quiet = quiet
        self.closed = False

    def __call__(self, line: str) -> None:
        if self.quiet or self.closed:
            return
        try:
            print(line, flush=True)
        except BrokenPipeError:
            self.closed = True
            try:
                null = os.open(os.devnull, os.O_WRONLY)
                os.dup2(null, sys.stdout.fileno())
                os.close(null)
            except (OSError, ValueError):  # stdout without a descriptor (a test's capture)
                pass


@dataclass
class Status:
    """Where a run is, for the one line printed when it is interrupted, and its output."""

    problem: str = ""
    folder: RunFolder | None = None
    done: int = -1  # last level whose files are complete
    phase: str = "while starting"
    say: Callable[[str], None] = field(default_factory=Printer)
    last: Level | None = None  # the last level whose files are complete, if solved here

    def finished(self) -> str:
        """What finished, and where (``levels 0-5 finished in results/6.2``)."""
        out = self.folder.path if self.folder is not None else "no folder"
        if self.done < 0:
            return f"no level finished in {out}"
        levels = "level 0" if self.done == 0 else f"levels 0-{self.done}"
        return f"{levels} finished in {out}"

    def interrupted(self, how: str = "interrupted") -> str:
        if self.folder is None:
            return f"signorini: {how} before the run started; nothing was written"
        out = self.folder.path
        finished = self.finished()
        command = f"signorini run {shlex.quote(self.problem)} --resume {shlex.quote(str(out))}"
        return f"signorini: {how} {self.phase}; {finished}; continue with: {command}"


def write_levels(
    levels: Iterator[Level],
    history: HistoryWriter,
    folder: RunFolder,
    *,
    vtu: bool,
    save_state: bool,
    say: Callable[[str], None],
    status: Status | None = None,
    clock: Clock | None = None,
) -> Level | None:
    """Write each level as soon as it is done: its VTU file (if ``vtu``) and the ``.pvd``
    collections of the levels, then its history row with the seconds those files took as
    ``t_output``, then (if ``save_state``) the state to resume from. Returns the last level
    (None if there was none)."""
    last = None
    for level in levels:
        k = level.record.level
        t0 = time.perf_counter()
        if vtu:
            name = f"level_{k:03d}.vtu"
            folder.add_files(name, "levels.pvd", "levels_ndof.pvd")
            write_vtu(folder.path / name, level.result, level.estimate)
            done = [(int(r["level"]), int(r["ndof"])) for r in history.rows]
            write_pvd(folder.path, [*done, (k, int(level.record.ndof))])
        history.append({**level.record.row(), "t_output": time.perf_counter() - t0})
        if save_state:
            if level.next_mesh is None:  # the last level: keep its own mesh and solution
                folder.save_state(k, level.result.mesh, level.result.u, final=True)
            else:
                folder.save_state(k, level.next_mesh, level.next_u0, final=False)
        if status is not None:
            status.done, status.last = k, level
            status.phase = f"at level {k + 1}"
        line = progress(level)
        say(line + (clock.lap(level) if clock is not None else ""))
        if level.record.stop == "round-off":
            say(f"stopped at level {k}: {roundoff_text(level.record)}")
        last = level
    return last
