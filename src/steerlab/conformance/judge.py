r"""The verdict on one course change: steers, or fails with the reason.

A run of the matrix is a course change of :data:`CHANGE_DEG` at ``t_change``. With the
heading error after the change ``e(t) = psi(t) - psi_new`` (the heading unwrapped, so a spin
is not folded back), the run **steers** when

1. the judged error ``s(t)`` stays within :data:`TOL_DEG` over the whole *hold window*, the
   last ``hold`` seconds of the run (it settled before the window and stays there). In calm
   water ``s = e``. In waves the heading swings at the encounter frequency whatever the
   autopilot does, so ``s`` is ``e`` averaged over a triangular window of :data:`WAVE_WINDOW`
   seconds (about six peak periods of sea state 5, Tp = 9.7 s; :func:`course_made_good`): the
   course the ship makes good, which is what a course-keeping autopilot is asked to hold;
2. the rudder reversals after the change are at most :data:`MAX_REVERSALS_PER_MIN` a minute:
   a reversal is counted when the rudder, having moved one way, comes back by at least
   :data:`REVERSAL_HYST_DEG` (smaller dithers are not counted: they cost the gear little and
   a rate-limited gear integrates them). Six a minute is one every ten seconds, the "few
   reversals a minute at most" of issue 30; IMO's performance standard for heading control
   systems asks that a preset heading be kept "with minimum operation of the ship's steering
   gear" (Res. A.342(IX) as amended by MSC.64(67), Annex 3, 2.1).

Otherwise it **fails**, with the first reason that applies, checked in this order:

* ``diverged``: a state left the finite numbers (time and what);
* ``spins``: the heading ran more than :data:`SPIN_DEG` from the new course;
* ``never turns``: the heading never made half the change (:data:`TURN_FRACTION`);
* ``limit cycle``: in the hold window the judged error swings about its mean, crossing it
  at least :data:`CYCLE_CROSSINGS` times (amplitude, offset, period and rudder amplitude given);
* ``steady offset``: it stays put, but more than :data:`TOL_DEG` off the new course;
* ``not settled``: still moving (a slow convergence or a drift) at the end of the run;
* ``rudder reversals``: the heading holds, the rudder works more than the bound allows.

Everything here works on arrays of one run (NumPy); it does not run anything.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

CHANGE_DEG = 20.0
"""The course change of every run [deg] (to starboard)."""
TOL_DEG = 1.0
"""Settled: the judged heading error within this [deg]."""
WAVE_WINDOW = 60.0
"""Support of the triangular window that gives the judged heading error in waves [s]
(:func:`course_made_good`)."""
REVERSAL_HYST_DEG = 0.5
"""A rudder reversal counts once the rudder came back this far from its last extreme [deg]."""
MAX_REVERSALS_PER_MIN = 6.0
"""Bound on the rudder reversals after the change [1/min]."""
SPIN_DEG = 180.0
"""The heading this far from the new course [deg] at any time: the ship spins."""
TURN_FRACTION = 0.5
"""Never turns: the heading never made this fraction of the change."""
CYCLE_CROSSINGS = 4
"""A limit cycle: the judged error crosses its hold-window mean at least this often (2 periods)."""
STEADY_PTP_DEG = 0.5
"""A steady offset: the judged error moves less than this [deg] over the hold window."""

STEERS = "steers"
FAILS = "fails"
REFUSED = "refused"
VERDICTS = (STEERS, REFUSED, FAILS)


@dataclass(frozen=True)
class Judgement:
    """The verdict on one run.

    Attributes
    ----------
    verdict : str
        ``"steers"`` or ``"fails"`` (``"refused"`` is given by the matrix, not by a run).
    reason : str
        Empty when it steers; else the failure kind first (``"limit cycle: ..."``).
    metrics : dict
        ``settle_time`` [s after the change; NaN if it never settles], ``final_error_deg``
        (judged error at the end), ``max_error_deg`` (largest raw error after the change),
        ``reversals_per_min``, ``max_rudder_deg``.
    """

    verdict: str
    reason: str = ""
    metrics: dict = field(default_factory=dict)

    @property
    def kind(self) -> str:
        """The failure kind (``"limit cycle"``, ...), empty when it steers."""
        return self.reason.split(":", 1)[0]


def trailing_mean(t: np.ndarray, y: np.ndarray, window: float) -> np.ndarray:
    """Mean of ``y`` over ``(t - window, t]`` (uniform samples; shorter at the start)."""
    dt = float(t[1] - t[0]) if len(t) > 1 else 1.0
    n = max(1, int(round(window / dt)))
    c = np.concatenate(([0.0], np.cumsum(y)))
    k = np.arange(1, len(y) + 1)
    lo = np.maximum(k - n, 0)
    return (c[k] - c[lo]) / (k - lo)


def course_made_good(t: np.ndarray, e: np.ndarray, window: float = WAVE_WINDOW) -> np.ndarray:
    r"""The heading error with the wave-frequency yaw averaged out: ``e`` through a trailing
    triangular window of support ``window`` [s], i.e. two trailing means of ``window / 2`` in
    cascade.

    Why not one trailing mean of ``window``: a boxcar of length ``L`` passes a sinusoid of period
    ``P`` with gain ``|sinc(L / P)|`` (``sin(pi x) / (pi x)``), whose side lobes fall only as
    ``P / (pi L)``: at ``L = 60 s`` up to 5 % of a 9-s wave yaw is left, and on a small ship in sea
    state 5, which yaws 5.8 deg (std) at a 9-s encounter period whatever its autopilot does
    (the Zeefakkel at 3.9 kn, issue 30), that is a +-0.55 deg ripple, half the 1 deg tolerance,
    counted against the autopilot. Two means of ``L / 2`` in cascade have the gain
    ``sinc(L / (2 P))^2``: at most 0.9 % of the 9-s wave yaw is left, and a slow swing of the course
    itself (a real limit cycle of period 120 s) is passed with 0.81 of its amplitude where the
    60-s boxcar passed 0.64: the measure is closer to the course made good on both sides.
    The window's delay is ``L / 2`` as the boxcar's.
    """
    half = 0.5 * float(window)
    return trailing_mean(t, trailing_mean(t, e, half), half)


def count_reversals(delta: np.ndarray, hysteresis: float) -> int:
    """Direction reversals of the rudder ``delta`` [rad] with a hysteresis [rad].

    The rudder's direction is set once it has moved ``hysteresis`` from its last extreme;
    each change of that direction is one reversal.
    """
    d = np.asarray(delta, dtype=float)
    if d.size < 2:
        return 0
    direction = 0                  # +1 rising, -1 falling, 0 not yet known
    hi = lo = ext = float(d[0])
    n = 0
    # only the samples where the rudder moves (a held rudder changes nothing)
    for v in d[np.flatnonzero(np.diff(d, prepend=d[0]) != 0.0)].tolist():
        if direction == 0:
            hi, lo = max(hi, v), min(lo, v)
            if v - lo >= hysteresis:
                direction, ext = 1, v
            elif hi - v >= hysteresis:
                direction, ext = -1, v
        elif direction > 0:
            if v > ext:
                ext = v
            elif ext - v >= hysteresis:
                n, direction, ext = n + 1, -1, v
        else:
            if v < ext:
                ext = v
            elif v - ext >= hysteresis:
                n, direction, ext = n + 1, 1, v
    return n


class ReversalCounter:
    """:func:`count_reversals` for N rudders at once, fed one sample at a time (same counts).

    ``update(delta)`` with the (N,) rudder angles [rad] of the next sample; ``count`` (N,)
    holds the reversals so far.
    """

    def __init__(self, delta0: np.ndarray, hysteresis: float) -> None:
        d = np.array(delta0, dtype=float)
        self.h = float(hysteresis)
        self.direction = np.zeros(d.shape)
        self.hi, self.lo, self.ext = d.copy(), d.copy(), d.copy()
        self.count = np.zeros(d.shape, dtype=np.int64)

    def update(self, delta: np.ndarray) -> None:
        d = np.asarray(delta, dtype=float)
        h, direction, ext = self.h, self.direction, self.ext
        unknown = direction == 0.0
        self.hi = np.where(unknown, np.maximum(self.hi, d), self.hi)
        self.lo = np.where(unknown, np.minimum(self.lo, d), self.lo)
        up0 = unknown & (d - self.lo >= h)
        down0 = unknown & ~up0 & (self.hi - d >= h)
        rising, falling = direction > 0.0, direction < 0.0
        back_down = rising & (ext - d >= h)
        back_up = falling & (d - ext >= h)
        self.count += back_down | back_up
        turned = up0 | down0 | back_down | back_up
        self.ext = np.where(turned | (rising & (d > ext)) | (falling & (d < ext)), d, ext)
        self.direction = np.where(up0 | back_up, 1.0, np.where(down0 | back_down, -1.0, direction))


def _crossings(t: np.ndarray, y: np.ndarray) -> tuple[int, float]:
    """``(sign changes of y, period [s])``: zeros skipped; the period from the first and last
    crossing (NaN with fewer than two)."""
    keep = np.sign(y) != 0.0
    s, tk = np.sign(y)[keep], t[keep]
    at = np.flatnonzero(s[1:] != s[:-1])
    n = int(at.size)
    period = 2.0 * float(tk[at[-1] + 1] - tk[at[0] + 1]) / (n - 1) if n >= 2 else math.nan
    return n, period


def judge(time, psi, delta, t_change: float, psi_old: float, psi_new: float, hold: float,
          waves: bool, reversals: int | None = None) -> Judgement:
    """The verdict on one course change (see the module docstring).

    Parameters
    ----------
    time : (n,) array [s]
    psi : (n,) array [rad]
        Heading (wrapped or not: it is unwrapped here).
    delta : (n,) array [rad]
        Rudder angle (the gear's output).
    t_change : float
        Time of the change [s].
    psi_old, psi_new : float
        Heading before and set heading after the change [rad].
    hold : float
        Length of the hold window at the end of the run [s].
    waves : bool
        Judge the course made good, :func:`course_made_good` (a sea) or the heading itself (calm).
    reversals : int, optional
        The rudder reversals after the change, counted elsewhere on every step
        (:class:`ReversalCounter`) when ``delta`` is a decimated log; default: counted here.

    Returns
    -------
    Judgement
    """
    t = np.asarray(time, dtype=float)
    psi = np.asarray(psi, dtype=float)
    delta = np.asarray(delta, dtype=float)
    bad = ~(np.isfinite(psi) & np.isfinite(delta))
    if bad.any():
        k = int(np.argmax(bad))
        return Judgement(FAILS, f"diverged: the state left the finite numbers at t = {t[k]:.4g} s")
    after = t >= t_change
    ta = t[after]
    e = np.unwrap(psi)[after] - psi_new
    # the unwrapped heading may start a whole turn away from psi_new's branch
    e -= 2.0 * math.pi * round(float(e[0] + psi_new - psi_old) / (2.0 * math.pi))
    s = course_made_good(ta, e) if waves else e
    deg = 180.0 / math.pi
    change = psi_new - psi_old
    moved = (e + psi_new - psi_old) * math.copysign(1.0, change)   # progress towards the new course
    in_hold = ta >= ta[-1] - hold
    sh = s[in_hold] * deg
    out_tol = np.flatnonzero(np.abs(s) * deg > TOL_DEG)
    settle = 0.0 if out_tol.size == 0 else (ta[out_tol[-1]] - t_change if out_tol[-1] + 1 < len(ta) else math.nan)
    minutes = max((ta[-1] - t_change) / 60.0, 1e-9)
    if reversals is None:
        reversals = count_reversals(delta[after], math.radians(REVERSAL_HYST_DEG))
    rev = reversals / minutes
    metrics = {"settle_time": float(settle), "final_error_deg": float(s[-1] * deg),
               "max_error_deg": float(np.max(np.abs(e)) * deg), "reversals_per_min": float(rev),
               "max_rudder_deg": float(np.max(np.abs(delta[after])) * deg)}
    big = np.flatnonzero(np.abs(e) * deg > SPIN_DEG)
    if big.size:
        return Judgement(FAILS, f"spins: the heading ran {np.max(np.abs(e)) * deg:.0f} deg from the new "
                                f"course (past {SPIN_DEG:g} deg at t = {ta[big[0]]:.4g} s)", metrics)
    if np.max(moved) < TURN_FRACTION * abs(change):
        return Judgement(FAILS, f"never turns: the heading made {np.max(moved) * deg:.3g} deg of the "
                                f"{abs(change) * deg:.3g} deg change", metrics)
    if np.max(np.abs(sh)) <= TOL_DEG:
        if rev > MAX_REVERSALS_PER_MIN:
            return Judgement(FAILS, f"rudder reversals: {rev:.3g} a minute (at most {MAX_REVERSALS_PER_MIN:g}; "
                                    f"hysteresis {REVERSAL_HYST_DEG:g} deg)", metrics)
        return Judgement(STEERS, "", metrics)
    what = "mean heading" if waves else "heading"
    mean = float(np.mean(sh))
    crossings, period = _crossings(ta[in_hold], sh - mean)
    ptp = float(np.ptp(sh))
    if crossings >= CYCLE_CROSSINGS and ptp > STEADY_PTP_DEG:
        amp_d = 0.5 * float(np.ptp(delta[after][in_hold])) * deg
        return Judgement(FAILS, f"limit cycle: {what} +-{0.5 * ptp:.2g} deg about {mean:+.2g} deg off the new "
                                f"course, period about {period:.3g} s, rudder +-{amp_d:.2g} deg", metrics)
    if ptp <= STEADY_PTP_DEG:
        return Judgement(FAILS, f"steady offset: the {what} stays {mean:+.3g} deg off the new course", metrics)
    return Judgement(FAILS, f"not settled: {what} error from {np.min(sh):+.3g} to {np.max(sh):+.3g} deg in the "
                            f"last {hold:.4g} s (end {sh[-1]:+.3g} deg)", metrics)
