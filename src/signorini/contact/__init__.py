"""The discrete contact problem of one mesh: constrained nodes and their weights, node
frames, the assembled system, the SOLVE step that returns a :class:`ContactResult`, and
quasi-static load paths (:func:`solve_path`)."""

from .load_path import solve_path
from .solution import ContactProfile, ContactResult, solve
from .system import Assembled, assemble

__all__ = ["Assembled", "ContactProfile", "ContactResult", "assemble", "solve", "solve_path"]
