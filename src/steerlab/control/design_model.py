r"""The design model every law's default gains come from, and the closed-loop bandwidth rule.

One :class:`DesignModel` per (ship, speed, gear): the first-order Nomoto model
(Nomoto et al. 1957)::

    T r' + r = K delta        <=>     r' = -a r + b delta,    a = 1 / T  [1/s],  b = K / T  [1/s^2]

with its signs kept (a course-unstable ship has ``T < 0``, usually ``K < 0`` too, and then
``a < 0``; ``b > 0`` for every ship in steerlab's sign convention), the second-order reading
``T1, T2, T3`` where the ship has one, the rudder efficiency ``b2`` (the yaw acceleration per
radian of rudder at the first instant), and the steering gear's limit, rate and servo lag.
Laws design in the ``(a, b)`` form: it stays well conditioned when ``|T|`` is very large
(a nearly marginal ship: the Esso tanker's first-order ``T`` is about -409 s, KVLCC2's about
-3 700 s, while ``b`` is finite).

:func:`bandwidth` states the one rule for the closed-loop natural frequency ``omega_n``
[rad/s] shared by every law: it follows the ship's response to its rudder ``b = K/T`` and is
capped by what the steering gear can deliver in the reference turn (its limit, its rate limit
and its servo lag).
For a course-unstable ship it must exceed the unstable pole by a margin; where the gear caps
are below that margin the loop is designed at a smaller one all the same and the gear
saturates in the reference turn, provided the yaw rate the saturated loop asks for stays below the
largest one the rudder can hold (:func:`unstable_turn_rate`); otherwise the design is refused
in one line that says which gear would do.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from steerlab.errors import InputError
from steerlab.units import deg, rad

#: The reference turn a design must be able to follow without saturating the gear [rad]
#: (the 20 deg course change of the conformance matrix and of the papers' scenarios).
DESIGN_TURN = rad(20.0)
#: Relative damping of the designed closed loop [-] (Fossen 2011, Sec. 12.2.7: 0.8-1.0).
ZETA = 0.9
#: A course-unstable ship: ``omega_n`` at least this many times its unstable pole ``|a|``.
UNSTABLE_MARGIN = 2.0
#: A course-unstable ship whose gear cannot give ``UNSTABLE_MARGIN |a|``: ``omega_n`` at least
#: this many times ``|a|``. A PD loop ``s^2 + (2 zeta omega_n) s + omega_n^2`` on a ship with
#: the pole ``+|a|`` stays stable for loop gains down to ``|a| / (2 zeta omega_n + |a|)`` (the
#: rudder's saturation lowers the gain): at ``1.2 |a|`` down to 0.32, a lower gain margin of
#: about 10 dB (Fossen 2011, Sec. 12.2.7, PD on the Nomoto model; the lower margin of an
#: open-loop unstable plant, Skogestad & Postlethwaite 2005, Sec. 2.4).
UNSTABLE_FLOOR = 1.2
#: Fraction of the gear's limit a design may command in the reference turn [-].
GEAR_USE = 0.7
#: ``omega_n`` at most this fraction of the servo's bandwidth ``1/T_sg`` [-] (Fossen 2011,
#: Sec. 12.2.7: the closed-loop bandwidth below the steering machine's ``omega_delta``).
SERVO_FRACTION = 0.3


@dataclass(frozen=True)
class DesignModel:
    """The linear model a design rule starts from (all SI, signs kept).

    Attributes
    ----------
    K : float
        First-order Nomoto gain [1/s].
    T : float
        First-order Nomoto time constant [s]; ``T < 0``: course-unstable.
    b2 : float
        Rudder efficiency [1/s^2]: yaw acceleration per rad of rudder (``K/T`` for a
        first-order model).
    delta_max, rate_max, T_sg : float
        The gear's limit [rad], rate limit [rad/s] and servo time constant [s].
    speed : float
        Design speed [m/s] (NaN when not given).
    T1, T2, T3 : float
        Second-order Nomoto reading [s] (NaN where the ship has none).
    source : str
        Where ``K``, ``T`` come from (for the design report).
    """

    K: float
    T: float
    b2: float
    delta_max: float
    rate_max: float
    T_sg: float
    speed: float = math.nan
    T1: float = math.nan
    T2: float = math.nan
    T3: float = math.nan
    source: str = ""

    @property
    def a(self) -> float:
        """``1/T`` [1/s]: the open-loop yaw-rate pole is ``-a`` (``a < 0``: course-unstable)."""
        return 1.0 / self.T

    @property
    def b(self) -> float:
        """``K/T`` [1/s^2]: the rudder gain of ``r' = -a r + b delta`` (``b2`` for a neutrally
        stable ship, ``K = T = inf``: ``r' = b2 delta``)."""
        return self.K / self.T if math.isfinite(self.T) else self.b2

    @property
    def unstable(self) -> bool:
        """Whether the model is course-unstable (``T < 0``)."""
        return self.T < 0.0


def design_model(ctx, K: float | None = None, T: float | None = None, source: str = "") -> DesignModel:
    """The :class:`DesignModel` of a design context (``K``/``T`` override the ship's).

    ``K`` and ``T`` may have either sign but must have the same one (``b = K/T > 0``: a rudder
    to starboard turns the ship to starboard); otherwise :class:`InputError` names
    ``controller.K``.
    """
    given = K is not None and T is not None
    if K is None or T is None:
        K0, T0 = ctx.nomoto()
        K = K0 if K is None else K
        T = T0 if T is None else T
    K, T = float(K), float(T)
    if math.isinf(K) and math.isinf(T) and K * T > 0.0 and not given:
        # a neutrally stable ship (the linear yaw damping is zero: Bech's c1 = 0): r' = b2 delta
        b2 = float(ctx.b2("exact"))
        if math.isfinite(b2) and b2 > 0.0:
            g = ctx.gear
            return DesignModel(K=K, T=T, b2=b2, delta_max=float(g.delta_max), rate_max=float(g.rate_max),
                               T_sg=float(g.T_sg), speed=float(ctx.speed),
                               source=source or "the ship's b2 (neutrally stable: K = T = inf)")
    if not (math.isfinite(K) and K != 0.0):
        raise InputError("controller.K", f"the design model needs a finite, non-zero K [1/s], got {K!r}")
    if not (math.isfinite(T) and T != 0.0):
        raise InputError("controller.T", f"the design model needs a finite, non-zero T [s], got {T!r}")
    if K / T <= 0.0:
        raise InputError("controller.K", f"K = {K:g} 1/s and T = {T:g} s have opposite signs (K/T must be "
                                         "> 0: starboard rudder turns to starboard); give both with one sign")
    try:
        b2 = float(ctx.b2("exact"))
    except (InputError, AttributeError, TypeError, ValueError):
        b2 = K / T
    if not (math.isfinite(b2) and b2 > 0.0) or given:
        b2 = K / T
    g = ctx.gear
    return DesignModel(K=K, T=T, b2=b2, delta_max=float(g.delta_max), rate_max=float(g.rate_max),
                       T_sg=float(g.T_sg), speed=float(ctx.speed),
                       source=source or ("controller.K, controller.T" if given else "the ship's Nomoto model"))


def bandwidth_caps(m: DesignModel, turn: float = DESIGN_TURN) -> dict:
    """The bounds of ``omega_n`` [rad/s], by name.

    * ``limit``: a PD closed loop starts a step of ``turn`` with ``delta = omega_n^2 turn / b``;
      at most ``GEAR_USE`` of the gear's limit: ``omega_n <= sqrt(GEAR_USE delta_max b / turn)``;
    * ``rate``: that rudder is reached in about ``1/omega_n``: ``omega_n^3 turn / b <=
      GEAR_USE rate_max``;
    * ``servo``: ``SERVO_FRACTION / T_sg``.
    """
    b = m.b
    return {"limit": math.sqrt(GEAR_USE * m.delta_max * b / turn),
            "rate": (GEAR_USE * m.rate_max * b / turn) ** (1.0 / 3.0),
            "servo": SERVO_FRACTION / m.T_sg}


def unstable_turn_rate(m: DesignModel, omega_n: float, turn: float = DESIGN_TURN) -> tuple[float, float]:
    """``(asked, held)`` [rad/s]: the yaw rate a saturated loop at ``omega_n`` asks for in the
    reference turn, and the largest the rudder can hold on a course-unstable ship.

    While the rudder is at its stop, a PD loop ``delta = Kp e - Kd r`` (pole placement,
    :mod:`steerlab.control.pole_placement`) turns the ship towards ``Kp e = Kd r``: at the start
    of the turn ``r = (Kp/Kd) turn = omega_n^2 turn / (2 zeta omega_n - a)`` (``asked``). A
    course-unstable ship ``r' = |a| r + b delta`` can be brought back from a yaw rate only
    while ``b delta_max > |a| |r|``: ``held = b delta_max / |a| = |K| delta_max``. A loop that
    asks for more loses the ship at the stops (it spins); one that asks for less turns at
    that rate and settles (van Amerongen 1982, Sec. 3.2: the rudder must overcome the ship's
    instability; the steady yaw rate of a Nomoto ship is ``K delta``).
    """
    asked = omega_n * omega_n * turn / (2.0 * ZETA * omega_n - m.a)
    return asked, m.b * m.delta_max / abs(m.a)


def require_servo_for_unstable(m: DesignModel, law: str = "", omega_n: float | None = None) -> None:
    """Refuse (:class:`InputError` naming ``gear.T_sg``) a course-unstable model whose loop must
    be faster than the servo allows: ``omega_n`` (default ``UNSTABLE_FLOOR |a|``) above the
    servo cap ``SERVO_FRACTION / T_sg`` (Fossen 2011, Sec. 12.2.7). A law with a rule of its
    own (asa) asks this too."""
    if not m.unstable:
        return
    w = UNSTABLE_FLOOR * abs(m.a) if omega_n is None else omega_n
    cap = SERVO_FRACTION / m.T_sg
    if w > cap:
        who = f"{law}: " if law else ""
        raise InputError("gear.T_sg", f"{who}the course-unstable design model (T = {m.T:.4g} s) needs "
                         f"omega_n >= {w:.3g} rad/s; a servo of T_sg = {m.T_sg:.3g} s allows "
                         f"{cap:.3g}: give T_sg <= {SERVO_FRACTION / w:.3g}")


def bandwidth(m: DesignModel, turn: float = DESIGN_TURN, law: str = "") -> float:
    """The closed-loop natural frequency ``omega_n`` [rad/s] of every law's default design.

    ``omega_n`` is the smallest of the gear caps (:func:`bandwidth_caps`): the ship enters
    through ``b = K/T`` (a ship that answers its rudder slowly gets a slower loop), the gear
    through its limit, rate and lag (Fossen 2011, Sec. 12.2.7: the closed-loop bandwidth
    above the ship's corner ``1/|T|`` and below the steering machine's). A course-unstable
    model also needs ``omega_n >= UNSTABLE_MARGIN |a|``: it is raised to that when the gear
    allows it. Where the gear's limit and rate caps are below that, ``omega_n`` is the larger
    of the gear cap and ``UNSTABLE_FLOOR |a|``: the rudder may saturate in the reference turn,
    which a course-unstable ship survives while the saturated loop asks for no more yaw rate
    than the rudder can hold (:func:`unstable_turn_rate`); otherwise :class:`InputError` names
    ``gear.delta_max`` with the value that would do (``gear.T_sg`` when the servo cap is below
    ``UNSTABLE_FLOOR |a|``: the servo cap is never exceeded).
    """
    caps = bandwidth_caps(m, turn)
    gear_cap = min(caps["limit"], caps["rate"], caps["servo"])
    w = gear_cap
    if m.unstable:
        need = UNSTABLE_MARGIN * abs(m.a)
        if need <= gear_cap:
            return gear_cap
        w = max(gear_cap, UNSTABLE_FLOOR * abs(m.a))
        who = f"{law}: " if law else ""
        require_servo_for_unstable(m, law, w)
        asked, held = unstable_turn_rate(m, w, turn)
        if asked > held:
            lim = asked * abs(m.a) / m.b
            raise InputError("gear.delta_max", f"{who}the course-unstable design model (K = {m.K:.4g} 1/s, T = "
                             f"{m.T:.4g} s) needs omega_n >= {w:.3g} rad/s, whose turn asks for "
                             f"{deg(asked):.3g} deg/s, and a {deg(m.delta_max):.3g} deg rudder holds at most "
                             f"|K| delta_max = {deg(held):.3g} deg/s: give delta_max_deg >= {deg(lim):.3g}")
        return w        # above the gear's limit/rate caps: the rudder saturates in the reference turn
    return w


def nomoto_design_model(K, T, ctx) -> tuple[float, float]:
    """``(K [1/s], T [s])`` for a design rule: ``K``/``T`` where given (a controller's config),
    else the ship's first-order Nomoto model at the design speed (``ctx.nomoto()``).

    Raises :class:`InputError` naming ``controller.K`` / ``controller.T`` unless both are
    finite and > 0 (the rules that call this assume a course-stable design model; the
    :class:`DesignModel` path takes either sign).
    """
    if K is None or T is None:
        K0, T0 = ctx.nomoto()
        K = K0 if K is None else K
        T = T0 if T is None else T
    if not (math.isfinite(K) and K > 0.0):
        raise InputError("controller.K", f"the design model needs K > 0 [1/s], the ship gives {K!r}; set K")
    if not (math.isfinite(T) and T > 0.0):
        raise InputError("controller.T", f"the design model needs T > 0 [s] (course-stable), "
                         f"the ship gives {T!r}; set T")
    return float(K), float(T)
