"""Figures of the paper's Section 6 (and a few more), drawn from plain data on disk."""

from .figures import *  # noqa: F403
from .figures import __all__  # noqa: F401
