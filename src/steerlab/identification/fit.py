r"""Fit a Nomoto, Norrbin or Bech model to a trial record (thesis Sec. 2.5).

1. Static part (Norrbin, Bech): steady turns -> reversed spiral ``delta = H(r)`` by linear
   least squares (:mod:`.spiral`); needs at least 4 steady points (5 for the full cubic with
   ``c2``). Norrbin then has ``n1 = sign(c1)``, ``K = 1/|c1|`` and ``n_i = K c_i``; Bech uses
   ``H`` directly. Without enough steady points the static coefficients are fitted with the
   dynamics (symmetric ``c1 r + c3 r^3``; Norrbin tries ``n1 = +1`` and ``-1``).
2. Dynamic part: ``scipy.optimize.least_squares`` over the simulated response to the recorded
   rudder (:mod:`.response`: the same kernels and RK4 step as the simulator) minimising the
   yaw-rate error (thesis criterion 2.57), or the heading error when the record has no yaw
   rate.
3. Confidence intervals: ``+-1.96 sigma`` with ``cov = s^2 (J^T J)^-1`` from the Jacobian at
   the optimum, ``s^2`` = residual variance. Record noise is usually coloured (waves), so
   these intervals are optimistic; treat them as a lower bound on the uncertainty.

Parameters (SI): nomoto1 ``K`` [1/s], ``T`` [s]; nomoto2 ``K``, ``T1``, ``T2``, ``T3``;
norrbin ``K`` [1/s], ``T`` [s], ``n0`` [rad/s], ``n1`` [-], ``n2`` [s/rad], ``n3`` [s^2/rad^2];
bech ``a`` [1/s], ``b`` [1/s^3], ``T3`` [s], ``c0`` [rad], ``c1`` [s], ``c2`` [s^2/rad],
``c3`` [s^3/rad^2]. The starting point is a first-order ARX fit of the yaw rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from steerlab.errors import InputError
from steerlab.identification.record import Record
from steerlab.identification.response import simulate_response
from steerlab.identification.spiral import SpiralFit, fit_spiral, steady_points
from steerlab.ships import bech, nomoto1, nomoto2, norrbin

MODELS = ("nomoto1", "nomoto2", "norrbin", "bech")
UNITS = {"K": "1/s", "T": "s", "T1": "s", "T2": "s", "T3": "s", "n0": "rad/s", "n1": "-",
         "n2": "s/rad", "n3": "s^2/rad^2", "a": "1/s", "b": "1/s^3", "c0": "rad", "c1": "s",
         "c2": "s^2/rad", "c3": "s^3/rad^2"}


MAX_NRMSE = 0.3
"""A fit whose RMS residual exceeds this fraction of the fitted signal's standard deviation is bad."""
MAX_HEADING_RMS_DEG = 10.0
"""A fit whose heading RMS error exceeds this [deg] is bad."""
MAX_REL_CI = 0.5
"""A parameter whose 95 % half-width exceeds this fraction of its magnitude is poorly determined."""


@dataclass
class FitResult:
    """Identified parameters (SI) with 95 % intervals, the fit quality and the responses."""

    model: str
    params: dict                       # name -> value (SI), fitted and fixed
    ci95: dict                         # name -> half-width of the 95 % interval (fitted ones)
    fixed: dict                        # name -> how it was fixed ("spiral", "normalisation")
    fitted_on: str                     # "yaw_rate" or "heading"
    rms: float                         # RMS residual [rad/s or rad]
    rms_heading_deg: float
    rms_yaw_rate_deg_s: float
    spiral: SpiralFit | None
    t: np.ndarray = field(repr=False)
    psi_model: np.ndarray = field(repr=False)
    r_model: np.ndarray = field(repr=False)
    packed: np.ndarray = field(repr=False)
    target_std: float = math.nan       # standard deviation of the fitted signal [rad/s or rad]

    def quality(self) -> dict:
        """How far the numbers can be trusted (thresholds :data:`MAX_REL_CI`, :data:`MAX_NRMSE`,
        :data:`MAX_HEADING_RMS_DEG`).

        ``nrmse`` = RMS residual / standard deviation of the fitted signal; the fit is ``bad``
        when ``nrmse > MAX_NRMSE`` or the heading RMS error exceeds ``MAX_HEADING_RMS_DEG``:
        the model does not describe the record, so its intervals (which assume white residuals)
        mean nothing. A fitted parameter is ``poorly determined`` when its 95 % half-width
        exceeds ``MAX_REL_CI`` of its magnitude (or is not finite).
        """
        nrmse = self.rms / self.target_std if self.target_std > 0 else math.nan
        reasons = []
        if math.isfinite(nrmse) and nrmse > MAX_NRMSE:
            reasons.append(f"RMS residual is {nrmse:.2f} of the signal's spread (> {MAX_NRMSE:g})")
        if math.isfinite(self.rms_heading_deg) and self.rms_heading_deg > MAX_HEADING_RMS_DEG:
            reasons.append(f"heading RMS error {self.rms_heading_deg:.3g} deg (> {MAX_HEADING_RMS_DEG:g} deg)")
        poor = [k for k, h in self.ci95.items()
                if not (math.isfinite(h) and abs(h) <= MAX_REL_CI * abs(self.params.get(k, math.nan)))]
        return {"fit": "bad" if reasons else "ok", "nrmse": nrmse, "reasons": reasons,
                "poorly_determined": poor,
                "thresholds": {"max_nrmse": MAX_NRMSE, "max_heading_rms_deg": MAX_HEADING_RMS_DEG,
                               "max_relative_ci95": MAX_REL_CI}}

    def summary(self) -> dict:
        out = {"model": self.model, "fitted_on": self.fitted_on,
               "rms": self.rms, "rms_unit": "rad/s" if self.fitted_on == "yaw_rate" else "rad",
               "rms_heading_deg": self.rms_heading_deg, "rms_yaw_rate_deg_s": self.rms_yaw_rate_deg_s,
               "parameters": [{"name": k, "value": v, "unit": UNITS.get(k, ""),
                               "ci95": self.ci95.get(k), "fixed_by": self.fixed.get(k)}
                              for k, v in self.params.items()],
               "ci_note": "95 % intervals from the Jacobian, white-noise assumption (optimistic "
                          "for coloured noise)",
               "quality": self.quality()}
        q = out["quality"]
        for p in out["parameters"]:
            if p["fixed_by"] is None:
                p["poorly_determined"] = p["name"] in q["poorly_determined"]
        if self.spiral is not None:
            out["spiral"] = {"coef": self.spiral.coef, "stderr": self.spiral.stderr,
                             "n_points": int(len(self.spiral.points)), "rms_rad": self.spiral.rms}
        return out


def arx_nomoto(rec: Record) -> tuple[float, float]:
    """First-order Nomoto ``(K, T)`` from ``r[k+1] = alpha r[k] + beta delta[k]`` (start guess)."""
    r = rec.yaw_rate_estimate()
    A = np.column_stack([r[:-1], rec.delta[:-1]])
    (alpha, beta), *_ = np.linalg.lstsq(A, r[1:], rcond=None)
    dt = rec.dt
    if not (0.0 < alpha < 1.0):
        alpha = math.exp(-dt / 30.0)
    T = -dt / math.log(alpha)
    K = beta / (1.0 - alpha)
    if not (K > 0) or not math.isfinite(K):
        K = max(np.max(np.abs(r)) / max(np.max(np.abs(rec.delta)), 1e-6), 1e-4)
    return float(K), float(min(max(T, 2 * dt), 1e4))


class _Problem:
    """One model's free parameters, fixed ones and packing."""

    def __init__(self, rhs, n_states, names, x0, lo, hi, pack, extra0, fixed=None, scale=None):
        self.rhs, self.n_states, self.names = rhs, n_states, list(names)
        self.x0, self.lo, self.hi = np.asarray(x0, float), np.asarray(lo, float), np.asarray(hi, float)
        self.pack, self.extra0 = pack, extra0
        self.fixed = fixed or {}
        self.scale = np.abs(self.x0) if scale is None else np.asarray(scale, float)
        self.scale = np.where(self.scale > 0, self.scale, 1.0)


def _params_dict(model, theta, names, fixed_values):
    d = dict(fixed_values)
    d.update({n: float(v) for n, v in zip(names, theta)})
    order = {"nomoto1": ["K", "T"], "nomoto2": ["K", "T1", "T2", "T3"],
             "norrbin": ["K", "T", "n0", "n1", "n2", "n3"],
             "bech": ["a", "b", "T3", "c0", "c1", "c2", "c3"]}[model]
    return {k: d[k] for k in order}


def _problems(model: str, rec: Record, spiral: SpiralFit | None):
    """Candidate problems, the best fit wins (Norrbin without a spiral: n1 = +1 and n1 = -1;
    nomoto2: several splits of the ARX time constant into T1, T2, T3)."""
    K0, T0 = arx_nomoto(rec)
    d0 = float(rec.delta[0])
    if model == "nomoto1":
        return [(_Problem(nomoto1.nomoto1_rhs, 6, ["K", "T"], [K0, T0], [1e-6, 1e-3], [100.0, 1e5],
                          lambda th: np.array([th[0], th[1]]), lambda th, r0: None), {})]
    if model == "nomoto2":
        def pack2(th):
            return nomoto2.pack_params(*th)

        def extra2(th, r0):
            K, T1, T2, T3 = th
            a, b = (T1 + T2) / (T1 * T2), K / (T1 * T2)
            return [a * r0 - b * T3 * d0]      # z with r' = 0 at the start
        # several starts: T = T1 + T2 - T3 held at the ARX value, T2 and T3 varied
        starts = [(0.1, 0.1), (0.15, 0.3), (0.3, 0.15), (0.05, 0.25)]
        return [(_Problem(nomoto2.nomoto2_rhs, 7, ["K", "T1", "T2", "T3"],
                          [K0, T0 * (1 - f2 + f3), f2 * T0, f3 * T0], [1e-6, 1e-2, 1e-2, 0.0],
                          [100.0, 1e5, 1e5, 1e5], pack2, extra2, scale=[K0, T0, 0.2 * T0, 0.2 * T0]), {})
                for f2, f3 in starts]
    if model == "norrbin":
        if spiral is not None:
            c = spiral.coef
            n1 = 1.0 if c["c1"] >= 0 else -1.0
            K = 1.0 / max(abs(c["c1"]), 1e-9)
            fixed = {"K": K, "n0": K * c["c0"], "n1": n1, "n2": K * c["c2"], "n3": K * c["c3"]}
            pk = lambda th: norrbin.pack_params(fixed["K"], th[0], fixed["n0"], fixed["n1"], fixed["n2"], 0.0,
                                                fixed["n3"])
            return [(_Problem(norrbin.norrbin_rhs, 6, ["T"], [T0], [1e-2], [1e5], pk, lambda th, r0: None),
                     {"values": fixed, "by": dict.fromkeys(fixed, "spiral")})]
        out = []
        rmax = max(float(np.max(np.abs(rec.yaw_rate_estimate()))), 1e-4)
        for n1 in (1.0, -1.0):
            pk = (lambda s: lambda th: norrbin.pack_params(th[0], th[1], 0.0, s, 0.0, 0.0, th[2]))(n1)
            out.append((_Problem(norrbin.norrbin_rhs, 6, ["K", "T", "n3"], [K0, T0, 0.1 / rmax ** 2],
                                 [1e-6, 1e-2, 0.0], [100.0, 1e5, 1e12], pk, lambda th, r0: None,
                                 scale=[K0, T0, 1.0 / rmax ** 2]),
                        {"values": {"n0": 0.0, "n1": n1, "n2": 0.0},
                         "by": {"n0": "symmetric", "n1": "normalisation", "n2": "symmetric"}}))
        return out
    if model == "bech":
        g = bech.from_nomoto2(K0, T0, 0.1 * T0, 0.1 * T0)

        def extra_b(a, b, T3, r0):
            return [a * r0 - b * T3 * d0]
        if spiral is not None:
            c = spiral.coef
            fixed = {k: c[k] for k in ("c0", "c1", "c2", "c3")}
            pk = lambda th: bech.pack_params(th[0], th[1], th[2], fixed["c0"], fixed["c1"], fixed["c2"], 0.0,
                                             fixed["c3"])
            return [(_Problem(bech.bech_rhs, 7, ["a", "b", "T3"], [g["a"], g["b"], g["T3"]],
                              [1e-4, 1e-9, 0.0], [100.0, 100.0, 1e5], pk,
                              lambda th, r0: extra_b(th[0], th[1], th[2], r0)),
                     {"values": fixed, "by": dict.fromkeys(fixed, "spiral")})]
        rmax = max(float(np.max(np.abs(rec.yaw_rate_estimate()))), 1e-4)
        pk = lambda th: bech.pack_params(th[0], th[1], th[2], 0.0, th[3], 0.0, 0.0, th[4])
        return [(_Problem(bech.bech_rhs, 7, ["a", "b", "T3", "c1", "c3"],
                          [g["a"], g["b"], g["T3"], g["c1"], 0.1 * g["c1"] / rmax ** 2],
                          [1e-4, 1e-9, 0.0, -1e4, 0.0], [100.0, 100.0, 1e5, 1e4, 1e12], pk,
                          lambda th, r0: extra_b(th[0], th[1], th[2], r0),
                          scale=[g["a"], g["b"], g["T3"], g["c1"], g["c1"] / rmax ** 2]),
                 {"values": {"c0": 0.0, "c2": 0.0}, "by": {"c0": "symmetric", "c2": "symmetric"}})]
    raise InputError("--model", f"must be one of {list(MODELS)}, got {model!r}")


def identify(rec: Record, model: str, use_spiral: bool | None = None, settle: float = 200.0,
             window: float = 100.0) -> FitResult:
    """Identify ``model`` from ``rec`` (see the module docstring).

    ``use_spiral``: None = use the steady turns when there are enough (>= 4), True = require
    them (InputError otherwise), False = fit everything dynamically.
    """
    from scipy.optimize import least_squares

    if model not in MODELS:
        raise InputError("--model", f"must be one of {list(MODELS)}, got {model!r}")
    spiral = None
    if model in ("norrbin", "bech") and use_spiral is not False:
        pts = steady_points(rec, settle=settle, window=window)
        if len(pts) >= 4:
            terms = ("c0", "c1", "c2", "c3") if len(pts) >= 5 else ("c0", "c1", "c3")
            spiral = fit_spiral(pts, terms)
        elif use_spiral:
            raise InputError("record", f"found {len(pts)} steady turns (rudder held >= {settle + window:g} s "
                                       "with a steady yaw rate); the spiral fit needs at least 4")
    on_rate = rec.r is not None
    target = rec.r if on_rate else rec.psi
    psi0 = float(rec.psi[0]) if rec.psi is not None else 0.0
    r0 = float(rec.yaw_rate_estimate()[0])
    speed = rec.mean_speed or 1.0

    # a heading-only record does not give the initial yaw rate: fit it (and the initial
    # heading) as nuisance parameters appended to the model's
    n_nuis = 0 if on_rate else 2
    best = None
    for prob, fixed in _problems(model, rec, spiral):
        def split(th, prob=prob):
            m = len(prob.x0)
            return th[:m], (th[m], th[m + 1]) if n_nuis else (psi0, r0)

        def residual(th, prob=prob):
            th_m, (p0, q0) = split(th)
            psi, r = simulate_response(prob.rhs, prob.n_states, prob.pack(th_m), rec.delta, rec.dt,
                                       p0, q0, prob.extra0(th_m, q0), speed)
            res = (r if on_rate else psi) - target
            return np.where(np.isfinite(res), res, 1e3)

        x0 = np.clip(prob.x0, prob.lo, prob.hi)
        lo, hi, sc = prob.lo, prob.hi, prob.scale
        if n_nuis:
            x0 = np.r_[x0, psi0, r0]
            lo, hi, sc = np.r_[lo, psi0 - 0.5, -0.2], np.r_[hi, psi0 + 0.5, 0.2], np.r_[sc, 1e-2, 1e-3]
        sol = least_squares(residual, x0, bounds=(lo, hi), x_scale=sc, method="trf",
                            max_nfev=300 * len(x0))
        if best is None or sol.cost < best[0].cost:
            best = (sol, prob, fixed, split)
    sol, prob, fixed, split = best
    n, p = len(target), len(sol.x)
    s2 = 2.0 * sol.cost / max(n - p, 1)
    try:
        cov = s2 * np.linalg.inv(sol.jac.T @ sol.jac)
        half = 1.96 * np.sqrt(np.maximum(np.diag(cov), 0.0))
    except np.linalg.LinAlgError:
        half = np.full(p, np.inf)
    th_m, (p0, q0) = split(sol.x)
    ps = prob.pack(th_m)
    psi_m, r_m = simulate_response(prob.rhs, prob.n_states, ps, rec.delta, rec.dt, p0, q0,
                                   prob.extra0(th_m, q0), speed)
    params = _params_dict(model, th_m, prob.names, fixed.get("values", {}))
    r_meas = rec.yaw_rate_estimate()
    rms_psi = math.degrees(float(np.sqrt(np.mean((psi_m - rec.psi) ** 2)))) if rec.psi is not None else math.nan
    return FitResult(model=model, params=params,
                     ci95={k: float(h) for k, h in zip(prob.names, half)},
                     fixed=fixed.get("by", {}), fitted_on="yaw_rate" if on_rate else "heading",
                     rms=float(np.sqrt(2.0 * sol.cost / n)), rms_heading_deg=rms_psi,
                     rms_yaw_rate_deg_s=math.degrees(float(np.sqrt(np.mean((r_m - r_meas) ** 2)))),
                     spiral=spiral, t=rec.t, psi_model=psi_m, r_model=r_m, packed=ps,
                     target_std=float(np.std(target)))
