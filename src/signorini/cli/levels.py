"""Each level of a run written as soon as it is done, its progress line, and where a run is
when it is interrupted."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from ..loop import Level
from ..output import HistoryWriter, write_vtu
from ..output.run import RunFolder

__all__ = ["Status", "progress", "write_levels"]


def progress(level: Level) -> str:
    """The progress line of a finished level."""
    r = level.record
    line = f"level {r.level:3d}  ndof {r.ndof:9d}  cells {r.n_cells:8d}  eta {r.eta:.4e}"
    if not np.isnan(r.error_energy):
        line += f"  error {r.error_energy:.4e}  eff {r.efficiency:.3f}"
    line += (
        f"  pdas {r.pdas_iterations:2d}  active {r.n_active:5d}"
        f"  [{r.t_assemble + r.t_solve + r.t_estimate + r.t_mark + r.t_refine:.2f}s]"
    )
    return line


@dataclass
class Status:
    """Where a run is, for the one line printed when it is interrupted."""

    problem: str = ""
    folder: RunFolder | None = None
    done: int = -1  # last level whose files are complete
    phase: str = "while starting"

    def interrupted(self) -> str:
        if self.folder is None:
            return "signorini: interrupted before the run started; nothing was written"
        out = self.folder.path
        if self.done < 0:
            finished = f"no level finished in {out}"
        else:
            levels = "level 0" if self.done == 0 else f"levels 0-{self.done}"
            finished = f"{levels} finished in {out}"
        return (
            f"signorini: interrupted {self.phase}; {finished}; continue with: "
            f"signorini run {self.problem} --resume {out}"
        )


def write_levels(
    levels: Iterator[Level],
    history: HistoryWriter,
    folder: RunFolder,
    *,
    vtu: bool,
    save_state: bool,
    say: Callable[[str], None],
    status: Status | None = None,
) -> Level | None:
    """Write each level as soon as it is done: its VTU file (if ``vtu``), then its history
    row with the seconds that file took as ``t_output``, then (if ``save_state``) the state
    to resume from. Returns the last level (None if there was none)."""
    last = None
    for level in levels:
        k = level.record.level
        t0 = time.perf_counter()
        if vtu:
            name = f"level_{k:03d}.vtu"
            folder.add_files(name)
            write_vtu(folder.path / name, level.result, level.estimate)
        history.append({**level.record.row(), "t_output": time.perf_counter() - t0})
        if save_state:
            if level.next_mesh is None:  # the last level: keep its own mesh and solution
                folder.save_state(k, level.result.mesh, level.result.u, final=True)
            else:
                folder.save_state(k, level.next_mesh, level.next_u0, final=False)
        if status is not None:
            status.done = k
            status.phase = f"at level {k + 1}"
        say(progress(level))
        last = level
    return last
