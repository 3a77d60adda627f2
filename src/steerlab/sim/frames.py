"""pandas DataFrames of results (pandas is imported here, on use: the optional extra ``pandas``)."""

from __future__ import annotations

import numpy as np


def _pandas():
    try:
        import pandas as pd
    except ImportError as err:  # pragma: no cover - depends on the environment
        raise RuntimeError("DataFrame export needs pandas: pip install 'steerlab[pandas]'") from err
    return pd


def result_frame(result):
    """One run as a DataFrame: index ``time [s]``, columns ``name [unit]`` (the CSV's columns, SI)."""
    pd = _pandas()
    cols = result.columns()
    index = pd.Index(np.asarray(cols.pop("time [s]")), name="time [s]")
    return pd.DataFrame({k: np.asarray(v) for k, v in cols.items()}, index=index)


def batch_frame(batch, lam: float = 0.1):
    """A batch as a DataFrame, one row per run (index ``run``): the integral metrics of
    :func:`steerlab.metrics.integral_metrics` (degrees, names carry their unit) and the final
    plant states ``<state>_final`` (SI)."""
    from steerlab.metrics import integral_metrics

    pd = _pandas()
    rows = [integral_metrics(a, lam) for a in np.asarray(batch.acc)]
    df = pd.DataFrame(rows, index=pd.RangeIndex(len(rows), name="run"))
    for j, name in enumerate(batch.state_names):
        df[f"{name}_final"] = np.asarray(batch.final_states)[:, j]
    return df
