"""ESTIMATE and MARK: the residual estimator η_h with its terms η1…η7 (paper, Section 5), the
H^{1/2}(Γ_C) norm it needs, and Dörfler marking."""

from .marking import mark_doerfler
from .residual import Estimate, estimate

__all__ = ["Estimate", "estimate", "mark_doerfler"]
