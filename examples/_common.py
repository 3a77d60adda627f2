"""Helpers shared by the gallery scripts: where to write, how long to run, a figure to draw on.

Every script takes ``--out DIR`` (default ``out/examples``) and ``--quick`` (short runs, used
by the test suite; also when the environment variable ``STEERLAB_EXAMPLES_QUICK=1``).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

HERE = Path(__file__).resolve().parent
SCENARIOS = HERE / "scenarios"
DATA = HERE / "data"


def parse_args(doc: str):
    p = argparse.ArgumentParser(description=doc.strip().splitlines()[0])
    p.add_argument("--out", default="out/examples", help="directory for the figure (default out/examples)")
    p.add_argument("--quick", action="store_true", help="short runs (for the test suite)")
    args = p.parse_args()
    args.quick = args.quick or os.environ.get("STEERLAB_EXAMPLES_QUICK") == "1"
    args.out = Path(args.out)
    args.out.mkdir(parents=True, exist_ok=True)
    return args


def figure(nrows: int = 1, ncols: int = 1, **kw):
    """A matplotlib figure without a display (Agg), and its axes."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=kw.pop("figsize", (8, 2.6 * nrows)), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=False, **kw)
    return fig, axes


def save(fig, path: Path) -> None:
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")
