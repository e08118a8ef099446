"""The discrete contact problem of one mesh: constrained nodes and their weights, node
frames, the assembled system, and the SOLVE step that returns a :class:`ContactResult`."""

from .solution import ContactProfile, ContactResult, solve
from .system import Assembled, assemble

__all__ = ["Assembled", "ContactProfile", "ContactResult", "assemble", "solve"]
