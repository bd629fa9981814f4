"""Whether a run reaches and holds the object or brushes it (docs/analysis.md, "Holding, per
run"; the threshold was written down before the confirmatory study ran): by its late-window
separations per successful trial, the window sum of the top 20's separations over the window
sum of their successful trials. ROS-free."""
from __future__ import annotations

import math

import numpy as np

from .stats import Estimate, share

LIMIT = 1.0            # at most one separation per reach: the run holds
HOLDS, BRUSHES, NO_REACH = "holds", "brushes", "does not reach"


def per_success(separations, successes) -> float:
    """Separations per successful trial over a window (NaN without a successful trial)."""
    below = float(np.nansum(successes))
    return float(np.nansum(separations)) / below if below > 0 else math.nan


def kind(ratio: float) -> str:
    """HOLDS, BRUSHES or NO_REACH for a run's late separations per successful trial."""
    if not np.isfinite(ratio):
        return NO_REACH
    return HOLDS if ratio <= LIMIT else BRUSHES


def holding_share(ratios) -> Estimate:
    """The share of runs that hold, with its Clopper-Pearson interval (a run that does not
    reach counts as not holding)."""
    return share([kind(r) == HOLDS for r in ratios])
