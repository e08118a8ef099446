"""signorini: adaptive quadratic finite elements for the Signorini contact problem."""

__version__ = "0.1.0"
