"""Files a run leaves behind: VTU solutions, the CSV history and its column description, the
run folder's manifest and resume state (:mod:`.run`), all written atomically."""

from .history import HistoryWriter, fitted_slope, read_history, write_columns
from .vtu import write_vtu

__all__ = ["HistoryWriter", "fitted_slope", "read_history", "write_columns", "write_vtu"]
