"""Figures and a static HTML report of one run; a plain-text metrics table for the terminal.

Each figure has a ``draw_*(ax, result, title)`` that draws into a given matplotlib Axes and
returns it (for notebooks and your own layouts) and a ``plot_*(path, result, title)`` that
writes it as a PNG. The files are drawn with matplotlib's Agg canvas (:class:`matplotlib.figure.Figure` +
:class:`~matplotlib.backends.backend_agg.FigureCanvasAgg`), never through ``pyplot``: nothing
depends on a display, no global figure registry grows, and a figure is freed as soon as it
goes out of scope. Degrees appear only here (the edge); the :class:`~steerlab.sim.result.Result`
stays SI / radians.

The HTML page is self-contained: inline CSS, images by relative links to the PNGs written
next to it, no scripts and no internet assets. All text is HTML-escaped.
"""

from __future__ import annotations

import html
import math
from numbers import Integral, Real
from pathlib import Path

import numpy as np

from steerlab.environment.channels import W_RUDDER
from steerlab.metrics import METRIC_UNITS

R2D = 180.0 / math.pi

FIGURE_NAMES = ("heading.png", "rudder.png", "yaw_rate.png", "track.png")
"""The files :func:`write_run_figures` writes, in order."""

TIME_SERIES_SIZE = (8.0, 3.5)
"""Figure size of the time-series plots [in]."""

TRACK_SIZE = (6.5, 6.5)
"""Figure size of the track plot [in]."""

DPI = 110

_META_KEYS = ("name", "ship", "controller", "engine", "dt", "controller_sample_time",
              "duration", "n_steps", "seed")

_FIGURE_ALT = {
    "heading.png": "Heading psi and reference heading psi_ref [deg] versus time",
    "rudder.png": "Rudder order, actual rudder angle and disturbance (equivalent rudder) [deg] versus time",
    "yaw_rate.png": "Yaw rate r and reference rate r_ref [deg/s] versus time",
    "track.png": "Ship track, east versus north",
}


# --------------------------------------------------------------------------------------------
# figures
# --------------------------------------------------------------------------------------------

def _new_figure(figsize=TIME_SERIES_SIZE):
    """A figure on its own Agg canvas and one axes.

    Returns
    -------
    fig : matplotlib.figure.Figure
    ax : matplotlib.axes.Axes
    """
    # matplotlib is imported here, not with the module: a run's figures are drawn in a forked
    # child (figure_worker) that imports it while the parent designs and simulates
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    # fixed margins, not layout="constrained": the constrained layout measures every text twice
    # and was half of the figures' time (0.3 of 0.6 s per run); the margins fit the labels
    fig = Figure(figsize=figsize, dpi=DPI)
    w, h = figsize
    fig.subplots_adjust(left=0.75 / w, right=1.0 - 0.2 / w, bottom=0.55 / h, top=1.0 - 0.4 / h)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    return fig, ax


def _save(fig, path: Path) -> Path:
    """Write ``fig`` as PNG and release its artists.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    path : pathlib.Path

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    fig.savefig(path, dpi=DPI, format="png")
    fig.clear()
    return path


def _title(ax, title: str, what: str) -> None:
    """Axes title ``"<title> - <what>"``; user text is never parsed as mathtext."""
    ax.set_title(f"{title} - {what}" if title else what, parse_math=False)


def unwrapped_heading_deg(psi, psi_ref):
    """Continuous (unwrapped) headings in degrees, on the same branch.

    Both series are unwrapped with :func:`numpy.unwrap`, then ``psi`` is shifted by a whole
    number of turns so that it starts within 180 deg of ``psi_ref``: a 359 -> 1 deg change
    plots as a 2 deg step and the two curves never sit a full turn apart.

    Parameters
    ----------
    psi, psi_ref : (N,) array_like
        Heading and reference heading [rad].

    Returns
    -------
    psi_deg, psi_ref_deg : (N,) numpy.ndarray
        [deg].
    """
    ref_u = np.unwrap(np.asarray(psi_ref, dtype=float))
    psi_u = np.unwrap(np.asarray(psi, dtype=float))
    if len(psi_u):
        psi_u = psi_u + 2.0 * math.pi * np.round((ref_u[0] - psi_u[0]) / (2.0 * math.pi))
    return psi_u * R2D, ref_u * R2D


def draw_heading(ax, result, title: str = ""):
    """Draw heading and reference heading [deg] versus time into ``ax``; returns ``ax``.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    result : steerlab.sim.result.Result
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    psi_deg, ref_deg = unwrapped_heading_deg(result.psi, result.psi_ref)
    ax.grid(True, alpha=0.4)
    ax.plot(result.time, ref_deg, "--", color="0.35", lw=1.2, label="psi_ref (set heading)")
    ax.plot(result.time, psi_deg, color="C0", lw=1.2, label="psi (heading)")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("heading [deg]")
    ax.legend(loc="best")
    _title(ax, title, "heading")
    return ax


def plot_result(result, axes=None, title: str = ""):
    """Heading, rudder and yaw rate of ``result`` (a :class:`~steerlab.sim.result.Result`) in
    three Axes (``axes``: three matplotlib Axes, or None for a new pyplot figure); returns the
    Axes (:func:`draw_heading`, :func:`draw_rudder`, :func:`draw_yaw_rate`). Here, not a method of
    the result: a result is data and imports no plotting (the layers, docs/architecture.md)."""
    if axes is None:
        import matplotlib.pyplot as plt

        _, axes = plt.subplots(3, 1, sharex=True, figsize=(8.0, 8.0), layout="constrained")
    if len(axes) != 3:
        from steerlab.errors import InputError
        raise InputError("axes", f"give three matplotlib Axes (heading, rudder, yaw rate), got {len(axes)}")
    for draw, ax in zip((draw_heading, draw_rudder, draw_yaw_rate), axes):
        draw(ax, result, title)
    return axes


def plot_heading(path: Path, result, title: str = "") -> Path:
    """Write :func:`draw_heading` as a PNG at ``path``; returns ``path``."""
    fig, ax = _new_figure()
    draw_heading(ax, result, title)
    return _save(fig, path)


def draw_rudder(ax, result, title: str = ""):
    """Draw rudder order, actual rudder angle and (if non-zero) the equivalent-rudder
    disturbance [deg] versus time into ``ax``; returns ``ax``.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    result : steerlab.sim.result.Result
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax.grid(True, alpha=0.4)
    dist = np.asarray(result.disturbance)
    handles = []
    if dist.ndim == 2 and dist.shape[1] > W_RUDDER and np.any(dist[:, W_RUDDER] != 0.0):
        d_deg = dist[:, W_RUDDER] * R2D
        rudder_span = max(float(np.max(np.abs(result.delta_cmd))), float(np.max(np.abs(result.delta))), 1e-9) * R2D
        # a first-order wave moment as an equivalent rudder can be many times the rudder limit:
        # then it gets its own (right) axis, so the rudder's work stays readable on the left
        dax = ax.twinx() if np.max(np.abs(d_deg)) > 2.0 * rudder_span else ax
        # drawn first and light: wave noise would otherwise hide the rudder curves
        handles += dax.plot(result.time, d_deg, color="C2", lw=0.7, alpha=0.45, zorder=1,
                            label="disturbance (equiv. rudder)" + (", right axis" if dax is not ax else ""))
        if dax is not ax:
            dax.set_ylabel("disturbance, equivalent rudder [deg]", color="C2")
            ax.set_zorder(dax.get_zorder() + 1)   # rudder curves above the disturbance
            ax.patch.set_visible(False)
    handles += ax.plot(result.time, result.delta_cmd * R2D, color="C1", lw=1.0, alpha=0.9, zorder=2,
                       label="delta_cmd (order)")
    handles += ax.plot(result.time, result.delta * R2D, color="C0", lw=1.3, zorder=3, label="delta (actual)")
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("rudder angle [deg]")
    ax.legend(handles=handles, loc="best")
    _title(ax, title, "rudder")
    return ax


def plot_rudder(path: Path, result, title: str = "") -> Path:
    """Write :func:`draw_rudder` as a PNG at ``path``; returns ``path``."""
    fig, ax = _new_figure()
    draw_rudder(ax, result, title)
    if len(fig.axes) > 1:                      # the disturbance's own axis: room for its labels
        fig.subplots_adjust(right=1.0 - 0.8 / TIME_SERIES_SIZE[0])
    return _save(fig, path)


def draw_yaw_rate(ax, result, title: str = ""):
    """Draw yaw rate and reference rate [deg/s] versus time into ``ax``; returns ``ax``.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    result : steerlab.sim.result.Result
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax.grid(True, alpha=0.4)
    ax.plot(result.time, result.r_ref * R2D, "--", color="0.35", lw=1.2, label="r_ref (reference)")
    ax.plot(result.time, result.r * R2D, color="C0", lw=1.2, label="r (yaw rate)")
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("yaw rate [deg/s]")
    ax.legend(loc="best")
    _title(ax, title, "yaw rate")
    return ax


def plot_yaw_rate(path: Path, result, title: str = "") -> Path:
    """Write :func:`draw_yaw_rate` as a PNG at ``path``; returns ``path``."""
    fig, ax = _new_figure()
    draw_yaw_rate(ax, result, title)
    return _save(fig, path)


def draw_track(ax, result, title: str = ""):
    """Draw the track: east (horizontal) versus north (vertical), equal aspect, start/end
    markers, into ``ax``; returns ``ax``.

    Metres for tracks up to 5 km across, kilometres beyond. A ship model without position
    states (``x_n``, ``y_e``) gets a placeholder saying so, so the report's links hold.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    result : steerlab.sim.result.Result
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax.grid(True, alpha=0.4)
    _title(ax, title, "track")
    if not {"x_n", "y_e"} <= set(result.state_names):
        ax.text(0.5, 0.5, "no position states (x_n, y_e) in this ship model",
                ha="center", va="center", transform=ax.transAxes)
        ax.set_axis_off()
        return ax
    north = result.col("x_n")
    east = result.col("y_e")
    extent = max(np.ptp(north), np.ptp(east)) if len(north) else 0.0
    scale, unit = (1e-3, "km") if extent > 5000.0 else (1.0, "m")
    ax.plot(east * scale, north * scale, color="C0", lw=1.2, label="track")
    ax.plot(east[0] * scale, north[0] * scale, "o", color="C2", ms=7, label="start")
    ax.plot(east[-1] * scale, north[-1] * scale, "s", color="C3", ms=7, label="end")
    from steerlab.track_figures import annotate_run
    annotate_run(ax, result, scale)      # route, berth and ship outlines when the run has them
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"east y_e [{unit}]")
    ax.set_ylabel(f"north x_n [{unit}]")
    ax.legend(loc="best")
    return ax


def plot_track(path: Path, result, title: str = "") -> Path:
    """Write :func:`draw_track` as a PNG at ``path``; returns ``path``."""
    fig, ax = _new_figure(TRACK_SIZE)
    draw_track(ax, result, title)
    return _save(fig, path)


_PLOTTERS = {
    "heading.png": plot_heading,
    "rudder.png": plot_rudder,
    "yaw_rate.png": plot_yaw_rate,
    "track.png": plot_track,
}


def write_run_figures(out_dir: Path, result, title: str = "", part: int = 0, parts: int = 1) -> list[Path]:
    """Write the run's PNG figures into ``out_dir`` (created if missing).

    Parameters
    ----------
    out_dir : pathlib.Path
        Output folder.
    result : steerlab.sim.result.Result
        The run.
    title : str, optional
        Prefix of every plot title (plain text, not mathtext).
    part, parts : int, optional
        Draw only the figures ``FIGURE_NAMES[part::parts]`` (one process's share).

    Returns
    -------
    list of pathlib.Path
        ``heading.png``, ``rudder.png``, ``yaw_rate.png``, ``track.png`` in ``out_dir`` (or the part's).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    return [_PLOTTERS[name](out_dir / name, result, title) for name in FIGURE_NAMES[part::parts]]


def warm_figures() -> None:
    """Import matplotlib and lay out one small figure with text (fonts, text engine), drawn
    to memory: what the first real figure of a process would otherwise pay."""
    fig, ax = _new_figure((2.0, 1.5))
    ax.set_title("steerlab", parse_math=False)
    ax.plot([0.0, 1.0], [0.0, 1.0])
    fig.canvas.draw()


def figure_worker():
    """A :class:`steerlab.figure_worker.FigureWorker` that draws :func:`write_run_figures`
    (``submit(out_dir, result, title)``) in one child, after importing matplotlib while the
    caller works. (Two children, two figures each, were slower on a 2-core machine: their
    warm-ups compete with the parent's design and simulation.) Once the result arrives, the
    child forks a grandchild and each draws two of the four figures (``split=2``): the
    parent is mostly waiting by then."""
    from steerlab.figure_worker import FigureWorker

    return FigureWorker(write_run_figures, warm=warm_figures, parts=1, split=2)


# --------------------------------------------------------------------------------------------
# metrics formatting
# --------------------------------------------------------------------------------------------

def _missing_text(name: str, metrics: dict) -> str:
    """What a ``None`` / NaN metric means: ``"not settled"`` for a settling time, else ``"n/a"``.

    The settling times are also ``None`` when the run has no set-point change (then the step
    metrics such as ``rise_time_s`` / ``overshoot_pct`` are ``None`` too): that is "n/a".
    """
    if name in ("settling_time_1deg_s", "settling_time_2pct_s"):
        has_step = metrics.get("overshoot_pct") is not None
        return "not settled" if has_step else "n/a"
    return "n/a"


def format_value(value) -> str:
    """A metric value as text: integers as is, floats to about 4 significant digits.

    Parameters
    ----------
    value : int, float, bool, str or None

    Returns
    -------
    str
        ``"n/a"`` for ``None`` and NaN.
    """
    if value is None:
        return "n/a"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, Integral):
        return str(int(value))
    if isinstance(value, Real):
        v = float(value)
        if math.isnan(v):
            return "n/a"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        if v == 0.0:
            return "0"
        a = abs(v)
        if a >= 1e7 or a < 1e-4:
            return f"{v:.3e}"
        decimals = min(6, max(0, 3 - math.floor(math.log10(a))))
        return f"{v:.{decimals}f}"
    return str(value)


def _metric_rows(metrics: dict) -> list[tuple[str, str, str]]:
    """``(name, value text, unit)`` for every metric, in dict order."""
    rows = []
    for name, value in metrics.items():
        missing = value is None or (isinstance(value, float) and math.isnan(value))
        text = _missing_text(name, metrics) if missing else format_value(value)
        rows.append((str(name), text, METRIC_UNITS.get(name, "")))
    return rows


def format_metrics_table(metrics: dict) -> str:
    """A plain-text table ``name | value | unit``, one line per metric (for the terminal).

    Parameters
    ----------
    metrics : dict
        As returned by :func:`steerlab.metrics.compute_metrics`.

    Returns
    -------
    str
        Aligned lines without a header, joined by newlines (no trailing newline). Values are
        right-aligned; ``None`` shows as ``not settled`` (settling times) or ``n/a``.
    """
    rows = _metric_rows(metrics)
    if not rows:
        return ""
    w_name = max(len(r[0]) for r in rows)
    w_val = max(len(r[1]) for r in rows)
    return "\n".join(f"{n:<{w_name}}  {v:>{w_val}}  {u}".rstrip() for n, v, u in rows)


# --------------------------------------------------------------------------------------------
# HTML
# --------------------------------------------------------------------------------------------

_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Helvetica, Arial, sans-serif;
       max-width: 60rem; margin: 2rem auto; padding: 0 1rem; color: #222; line-height: 1.4; }
h1 { font-size: 1.6rem; margin-bottom: 0.2rem; }
h2 { font-size: 1.2rem; margin-top: 2rem; border-bottom: 1px solid #ddd; }
p.description { color: #555; margin-top: 0; }
table { border-collapse: collapse; margin: 0.5rem 0; }
th, td { padding: 0.2rem 0.8rem; border-bottom: 1px solid #eee; text-align: left; }
td.value { text-align: right; font-variant-numeric: tabular-nums; }
th { background: #f4f4f4; }
figure { margin: 1rem 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #eee; }
figcaption { color: #555; font-size: 0.9rem; }
pre { background: #f7f7f7; padding: 0.8rem; overflow-x: auto; font-size: 0.85rem; }
""".strip()


def _e(x) -> str:
    """HTML-escaped text of anything."""
    return html.escape(str(x), quote=True)


def _meta_items(result, scenario) -> list[tuple[str, str]]:
    """``(key, text)`` pairs of the run's meta data shown in the report."""
    meta = dict(result.meta)
    if "duration" not in meta:
        meta["duration"] = (scenario.duration if scenario is not None
                            else float(result.time[-1] - result.time[0]) if len(result.time) else None)
    units = {"dt": " s", "controller_sample_time": " s", "duration": " s"}
    items = []
    for key in _META_KEYS:
        if key in meta and meta[key] is not None:
            value = meta[key]
            text = f"{value:g}" if isinstance(value, float) else format_value(value)
            items.append((key, text + units.get(key, "")))
    return items


def _html_meta(result, scenario) -> str:
    rows = "\n".join(f"<tr><th>{_e(k)}</th><td>{_e(v)}</td></tr>" for k, v in _meta_items(result, scenario))
    return f"<h2>Run</h2>\n<table class=\"meta\">\n{rows}\n</table>"


def _html_metrics(metrics: dict) -> str:
    rows = "\n".join(f"<tr><td>{_e(n)}</td><td class=\"value\">{_e(v)}</td><td>{_e(u)}</td></tr>"
                     for n, v, u in _metric_rows(metrics))
    return ("<h2>Metrics</h2>\n<table class=\"metrics\">\n"
            "<tr><th>metric</th><th>value</th><th>unit</th></tr>\n" f"{rows}\n</table>")


def _html_figures(paths) -> str:
    parts = ["<h2>Figures</h2>"]
    for p in paths:
        alt = _FIGURE_ALT.get(p.name, p.stem)
        parts.append(f"<figure><img src=\"{_e(p.name)}\" alt=\"{_e(alt)}\">"
                     f"<figcaption>{_e(alt)}</figcaption></figure>")
    return "\n".join(parts)


def _scenario_text(scenario) -> str:
    """The scenario as indented JSON (pydantic) or its ``repr``."""
    dump = getattr(scenario, "model_dump_json", None)
    return dump(indent=2) if callable(dump) else repr(scenario)


def _html_scenario(scenario) -> str:
    if scenario is None:
        return ""
    return f"<h2>Scenario</h2>\n<pre>{_e(_scenario_text(scenario))}</pre>"


def report_title(result, scenario=None) -> str:
    """The page and plot title: the scenario's name, else ``result.meta["name"]``."""
    return getattr(scenario, "name", None) or result.meta.get("name") or "steerlab run"


def write_run_report(out_dir: Path, result, metrics: dict, scenario=None,
                     title: str | None = None, figures: list[Path] | None = None) -> Path:
    """Write the run's figures and a self-contained ``report.html`` into ``out_dir``.

    Parameters
    ----------
    out_dir : pathlib.Path
        Output folder (created if missing).
    result : steerlab.sim.result.Result
        The run.
    metrics : dict
        As returned by :func:`steerlab.metrics.compute_metrics`.
    scenario : steerlab.sim.scenario.Scenario, optional
        Shown (name, description, full settings) when given.
    title : str, optional
        Page and plot title; default: the scenario name, else ``result.meta["name"]``.
    figures : list of pathlib.Path, optional
        The figures, already written (:func:`figure_worker`); default: drawn here.

    Returns
    -------
    pathlib.Path
        ``out_dir / "report.html"``.
    """
    out_dir = Path(out_dir)
    if title is None:
        title = report_title(result, scenario)
    if figures is None:
        figures = write_run_figures(out_dir, result, title)
    description = getattr(scenario, "description", "") if scenario is not None else ""
    name = getattr(scenario, "name", None) or result.meta.get("name", "")
    body = [f"<h1>{_e(title)}</h1>"]
    if name and name != title:
        body.append(f"<p class=\"description\">scenario: {_e(name)}</p>")
    if description:
        body.append(f"<p class=\"description\">{_e(description)}</p>")
    body += [_html_meta(result, scenario), _html_metrics(metrics), _html_figures(figures),
             _html_scenario(scenario)]
    page = ("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            f"<title>{_e(title)}</title>\n<style>\n{_CSS}\n</style>\n</head>\n<body>\n"
            + "\n".join(b for b in body if b) + "\n</body>\n</html>\n")
    path = out_dir / "report.html"
    path.write_text(page, encoding="utf-8")
    return path
