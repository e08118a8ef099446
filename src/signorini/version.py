"""The package's version, a bottom module: the package and its leaves read it from here."""

from __future__ import annotations

__all__ = ["__version__"]

#: the release, as ``pyproject.toml`` states it
__version__ = "0.1.0"
