"""Files a run leaves behind: VTU solutions, the CSV history, all written atomically."""

from .history import HistoryWriter
from .vtu import write_vtu

__all__ = ["HistoryWriter", "write_vtu"]
