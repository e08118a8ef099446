"""Files a run leaves behind: VTU solutions and the CSV history, all written atomically."""

from .history import HistoryWriter, fitted_slope, read_history
from .vtu import write_vtu

__all__ = ["HistoryWriter", "fitted_slope", "read_history", "write_vtu"]
