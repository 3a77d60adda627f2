"""Cost expressions over the run metrics: moved to :mod:`steerlab.costs` (shared by the tuner
and the sweeps, which no longer import each other); this name is kept for old imports."""

from steerlab.costs import (FUNCTIONS, LOGGED, METRIC_NAMES, ONLINE, PENALTY, REDUCERS,  # noqa: F401
                            CostExpression, metric_arrays, parse_cost)
