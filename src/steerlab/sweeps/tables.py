"""Writing sweep tables (CSV always, Parquet when pyarrow is installed) and figure canvases."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np


def write_table(stage: Path, stem: str, columns: dict, parquet: bool = True) -> list[Path]:
    """Write ``columns`` (name -> 1-D sequence, equal lengths) as ``stem.csv`` (+ ``stem.parquet``)."""
    names = list(columns)
    n = len(next(iter(columns.values()))) if columns else 0
    paths = []
    p = Path(stage) / f"{stem}.csv"
    with open(p, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(names)
        for i in range(n):
            w.writerow([_cell(columns[k][i]) for k in names])
    paths.append(p)
    if parquet:
        try:
            import pyarrow.parquet as pq
        except ImportError:  # pragma: no cover - optional
            return paths
        from steerlab.arrow_table import arrow_table

        q = Path(stage) / f"{stem}.parquet"
        pq.write_table(arrow_table({k: list(columns[k]) for k in names}), q)
        paths.append(q)
    return paths


def _cell(v):
    if isinstance(v, (float, np.floating)):
        return "" if not math.isfinite(float(v)) else repr(float(v))
    if isinstance(v, np.integer):
        return int(v)
    return v


def new_figure(figsize=(7.0, 4.5), nrows: int = 1):
    """A matplotlib Figure on its own Agg canvas (no pyplot state) and its axes."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, dpi=110, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, 1, squeeze=False)[:, 0]
    for ax in axes:
        ax.grid(True, alpha=0.4)
    return fig, axes


def save_figure(fig, path: Path) -> Path:
    fig.savefig(path, format="png")
    fig.clear()
    return Path(path)
