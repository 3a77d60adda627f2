r"""Run the conformance matrix: every catalogue ship x every built-in controller x calm and sea.

:func:`run_matrix` builds every :class:`~steerlab.conformance.cases.Case`, designs it the way
``steerlab run`` would (:func:`steerlab.sim.setup.build`: a design that raises
:class:`~steerlab.errors.InputError` is **refused**, its one line kept with the field it
names), runs it on the compiled engine and judges it
(:func:`steerlab.conformance.judge.judge`: **steers** or **fails** with the reason). Any
other exception, at design or run time, is a failure whose reason starts ``crashed:``: a
design must refuse bad input in one line, never raise something else.

Which engine. Each (ship kernel, control-law kernel) combination compiles one loop, kept in
the on-disk driver cache (docs/compile-cache.md), and that, not the runs, is the matrix's cost.
The sea leg runs each law behind the wave filter (``"<law>+wf"``); calm water runs the same
``"+wf"`` loop with the filter switched off (:func:`one_loop`: the law's own design, its orders
bit for bit those of its plain loop, tests/test_conformance_matrix.py), so the two legs share
one compiled loop: 132 loops from a cold cache instead of 228, 478 s of CPU instead of 573 for
the 1 804 cases, every outcome identical (2026-11-29, two processes, benchmarks/RESULTS.md).
The matrix uses the compiled single-run loop (``sl.simulate``), whose compile took 1.7-3.7 s of
CPU per combination where the batch engine's vectorised group loop took 4.3-6.7 s (four
combinations measured); a combination has 6-18 runs of 1-8 thousand simulated seconds, too few
for the vectorised loop to pay its compile back. The numbers are the same either way (the
engines are bit-identical, tests/test_engine.py). The loops are the ships' (they call each
law by address, :mod:`steerlab.jit.loop_calls`): the cases are spread over ``workers``
processes (default: 2, or the machine's cores if fewer) one ship per task, so no two
processes compile the same loop (only the laws' small sample entries, once in each).

What is run, by default: every operating point (:mod:`~steerlab.conformance.points`) in calm
water; the sea-state-5 leg at the points of ``sea_points`` (default: all three).
"""

from __future__ import annotations

import math
import os
import time
import warnings
from dataclasses import asdict, dataclass, field
from typing import Callable, Iterable, Optional

from steerlab.conformance.cases import (CALM, SEA5, T_CHANGE, Case, controller_type, run_length, scenario_dict,
                                        time_scale)
from steerlab.conformance.judge import CHANGE_DEG, FAILS, REFUSED, STEERS, VERDICTS, judge
from steerlab.conformance.points import operating_points

TARGET = 0.95
"""The fraction of cases that must steer (issue 30, "What must show")."""
SEA_POINTS = ("design", "low", "high")
"""Operating points that also get the sea-state-5 leg."""


@dataclass
class Outcome:
    """The verdict on one case, with what the table and the tests need (plain types).

    ``reason``: empty when it steers; the refusal's one line (``field: message``), or the
    failure's kind and detail. ``field_name``: the field a refusal names. ``metrics``: see
    :class:`~steerlab.conformance.judge.Judgement` (empty for a refusal). ``duration``,
    ``hold``: the run's length and hold window [s]; ``seconds``, ``cpu``: wall and CPU time of
    the design and run [s] (the first case of a combination includes its compile).
    """

    ship: str
    controller: str
    point: str
    speed_kn: float
    rpm: Optional[float]
    sea: str
    verdict: str
    reason: str = ""
    field_name: str = ""
    metrics: dict = field(default_factory=dict)
    duration: float = math.nan
    hold: float = math.nan
    seconds: float = math.nan
    cpu: float = math.nan

    @property
    def where(self) -> str:
        """``"16 kn"`` or ``"160 rpm"``."""
        return f"{self.rpm:g} rpm" if self.rpm is not None else f"{self.speed_kn:.3g} kn"

    def to_dict(self) -> dict:
        return asdict(self)


def builtin_ships() -> list[str]:
    """The ids of steerlab's own ships (modules and catalogue files; no plug-ins), sorted."""
    from steerlab.ships.registry import SHIPS

    return sorted(n for n, s in SHIPS.items() if getattr(s.rhs, "__module__", "").startswith("steerlab."))


NOT_DESIGNED = ("policy",)
"""Built-in controller types the matrix leaves out: ``policy`` runs a network trained for one
ship (the shipped one: the Esso tanker) and designs nothing for another; it is judged beside the
classical laws in its own experiment (``learning-vs-classical``, docs/learning.md)."""


def builtin_controllers() -> list[str]:
    """The types of steerlab's own control laws, without the ``+wf`` variants and
    :data:`NOT_DESIGNED`, sorted."""
    from steerlab.control.registry import CONTROLLERS

    return sorted(n for n, s in CONTROLLERS.items()
                  if "+" not in n and n not in NOT_DESIGNED
                  and getattr(s.update, "__module__", "").startswith("steerlab."))


def cases(ships: Iterable[str] | None = None, controllers: Iterable[str] | None = None,
          sea_points: Iterable[str] = SEA_POINTS) -> list[Case]:
    """Every case of the matrix, ship-major (see the module docstring)."""
    from steerlab.ships.registry import get_ship

    ships = builtin_ships() if ships is None else list(dict.fromkeys(ships))
    controllers = builtin_controllers() if controllers is None else list(dict.fromkeys(controllers))
    sea_points = set(sea_points)
    out = []
    for ship in ships:
        points = operating_points(get_ship(ship))
        for c in controllers:
            for p in points:
                out.append(Case(ship, c, p, CALM))
            for p in points:
                if p.label in sea_points:
                    out.append(Case(ship, c, p, SEA5))
    return out


def _one_line(err: BaseException) -> str:
    text = f"{type(err).__name__}: {err}"
    return text.splitlines()[0] if text.strip() else type(err).__name__


_SEAS: dict = {}
"""Per process: the disturbance sequence of each (ship, point, duration) in sea state 5."""


def build_case(case: Case, duration: float):
    """The :class:`~steerlab.sim.setup.SimSetup` of ``case`` (raises :class:`InputError`).

    The same as ``build(scenario)``, except that a sea already generated in this process for
    the same ship, point and length is reused: the sea (:func:`steerlab.environment.sea.add_sea`)
    depends on the ship, its speed, the course schedule and the seed, never on the controller,
    and generating it (400 wave components over every step) costs more than the run. The
    setup is then the calm scenario's (same design) with that sea's disturbance sequence;
    tests/test_conformance_matrix.py checks it equals the full build array for array.
    """
    from dataclasses import replace

    from steerlab.sim.scenario import scenario_from_dict
    from steerlab.sim.setup import build

    scenario = scenario_from_dict(scenario_dict(case, duration))
    if case.sea == CALM:
        return build(scenario)
    key = (case.ship, case.point, duration, case.sea)
    w = _SEAS.get(key)
    if w is None:
        setup = build(scenario)
        _SEAS[key] = setup.w
        return setup
    # the same scenario without its sea (the controller type is the sea case's: "+wf" in waves)
    calm = build(scenario_from_dict({k: v for k, v in scenario_dict(case, duration).items() if k != "environment"}))
    return replace(calm, w=w, name=scenario.name)


def run_case(case: Case) -> Outcome:
    """Design, run and judge one case in this process."""
    from steerlab.errors import InputError
    from steerlab.ships.registry import get_ship
    from steerlab.sim.engine import simulate

    t0, c0 = time.perf_counter(), time.process_time()
    spec = get_ship(case.ship)
    duration, hold = run_length(time_scale(spec, case.point))
    out = Outcome(case.ship, case.controller, case.point.label, case.point.speed_kn, case.point.rpm, case.sea,
                  FAILS, duration=duration, hold=hold)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # a speed at the end of a range warns; the verdict says
        try:
            setup = build_case(case, duration)
        except InputError as err:
            out.verdict, out.reason, out.field_name = REFUSED, str(err), err.field
            out.seconds, out.cpu = time.perf_counter() - t0, time.process_time() - c0
            return out
        except Exception as err:  # noqa: BLE001 - a design must refuse in one line: this is a defect
            out.reason = f"crashed: the design raised {_one_line(err)}"
            out.seconds, out.cpu = time.perf_counter() - t0, time.process_time() - c0
            return out
        try:
            res = simulate(one_loop(setup) if case.sea == CALM else setup)
        except Exception as err:  # noqa: BLE001
            out.reason = f"crashed: the run raised {_one_line(err)}"
            out.seconds, out.cpu = time.perf_counter() - t0, time.process_time() - c0
            return out
    k = full_scale_time(spec)
    j = judge(res.time * k, res.psi, res.delta, T_CHANGE * k, 0.0, math.radians(CHANGE_DEG), hold * k,
              case.sea == SEA5)
    out.verdict, out.reason, out.metrics = j.verdict, j.reason, j.metrics
    out.seconds, out.cpu = time.perf_counter() - t0, time.process_time() - c0
    return out


def one_loop(setup):
    """A calm-water ``setup`` run by its law's ``"+wf"`` loop with the filter off
    (:func:`steerlab.control.wave_filtered.filter_off`; the same design and, bit for bit, the
    same run), so that calm water and the sea leg of a (ship, law) share one compiled loop; the
    setup as it is where that does not apply (``asa``, a plant too large for the wrapper)."""
    from dataclasses import replace

    from steerlab.control.wave_filtered import filter_off

    off = filter_off(setup.controller, setup.pc, setup.z0, len(setup.x0))
    if off is None:
        return setup
    spec, pc, z0 = off
    return replace(setup, controller=spec, pc=pc, z0=z0)


def full_scale_time(spec) -> float:
    """Factor [-] from a run's time to the full-scale ship's: ``sqrt(lambda)`` for a scale model
    (``spec.model_scale`` = ``lambda``; Froude's law), else 1. A scale model's record is judged in
    full-scale time, so "six rudder reversals a minute" and the 60 s mean mean what they mean on
    the ship (the model's sea is Froude-scaled too: :func:`~steerlab.conformance.cases.sea_block`);
    its ``settle_time`` is reported in full-scale seconds."""
    lam = getattr(spec, "model_scale", None)
    return math.sqrt(lam) if lam else 1.0


def _run_task(task: list[Case]) -> list[Outcome]:
    return [run_case(c) for c in task]


def _kernel_key(case: Case) -> tuple:
    """The compiled loop a case needs: its ship's (by name), which calls every law by address
    (:mod:`steerlab.jit.loop_calls`; a law's sample entry is compiled once for all ships);
    where the loops inline the law, its ship's and its law's (calm water runs the sea leg's
    ``"+wf"`` loop, :func:`one_loop`)."""
    from steerlab.control.registry import get_controller
    from steerlab.jit.loop_calls import by_address
    from steerlab.ships.registry import get_ship

    rhs = get_ship(case.ship).rhs
    key = (getattr(rhs, "__module__", ""), getattr(rhs, "__name__", repr(rhs)))
    if by_address():
        return key
    update = get_controller(controller_type(case.controller, SEA5)).update
    return key + (getattr(update, "__module__", ""), getattr(update, "__name__", repr(update)))


def tasks(all_cases: list[Case]) -> list[list[Case]]:
    """The cases grouped by compiled loop (one task per ship, or per combination where the
    loops inline the law: :func:`_kernel_key`), biggest first."""
    groups: dict[tuple, list[Case]] = {}
    for c in all_cases:
        groups.setdefault(_kernel_key(c), []).append(c)
    return sorted(groups.values(), key=len, reverse=True)


@dataclass
class Matrix:
    """The outcomes of a matrix run (in case order) and its wall time [s]."""

    outcomes: list[Outcome]
    seconds: float = math.nan
    workers: int = 1

    def counts(self, by: str = "controller") -> dict[str, dict[str, int]]:
        """``{value of by: {"steers": n, "refused": n, "fails": n}}`` (``by``: an Outcome field)."""
        out: dict[str, dict[str, int]] = {}
        for o in self.outcomes:
            row = out.setdefault(getattr(o, by), {v: 0 for v in VERDICTS})
            row[o.verdict] += 1
        return dict(sorted(out.items()))

    def total(self) -> dict[str, int]:
        """``{"steers": n, "refused": n, "fails": n}`` over every case."""
        t = {v: 0 for v in VERDICTS}
        for o in self.outcomes:
            t[o.verdict] += 1
        return t

    @property
    def cpu_seconds(self) -> float:
        """CPU time of every case, summed over the processes [s] (compiles included)."""
        return float(sum(o.cpu for o in self.outcomes))

    @property
    def fraction_steers(self) -> float:
        """Cases that steer / all cases."""
        return self.total()[STEERS] / max(len(self.outcomes), 1)

    def to_dict(self) -> dict:
        return {"target": TARGET, "fraction_steers": self.fraction_steers, "total": self.total(),
                "by_controller": self.counts("controller"), "seconds": self.seconds, "cpu_seconds": self.cpu_seconds,
                "workers": self.workers,
                "outcomes": [o.to_dict() for o in self.outcomes]}


def default_workers() -> int:
    """2, or the machine's cores if fewer."""
    return max(1, min(2, os.cpu_count() or 1))


def run_matrix(ships: Iterable[str] | None = None, controllers: Iterable[str] | None = None,
               sea_points: Iterable[str] = SEA_POINTS, workers: int | None = None,
               progress: Optional[Callable[[int, int], None]] = None) -> Matrix:
    """Run the conformance matrix (module docstring).

    Parameters
    ----------
    ships, controllers : iterable of str, optional
        Default: every built-in ship (:func:`builtin_ships`) and law (:func:`builtin_controllers`).
    sea_points : iterable of str
        Operating points (``"design"``, ``"low"``, ``"high"``) that also run in sea state 5.
    workers : int, optional
        Processes (1: this one). Default :func:`default_workers`.
    progress : callable, optional
        ``progress(done, n)`` with the number of cases done.

    Returns
    -------
    Matrix
        Outcomes in case order (ship-major).
    """
    t0 = time.perf_counter()
    all_cases = cases(ships, controllers, sea_points)
    workers = default_workers() if workers is None else max(1, int(workers))
    done: dict[tuple, Outcome] = {}
    n = len(all_cases)
    if workers == 1 or len(all_cases) <= 1:
        for task in tasks(all_cases):
            for c, o in zip(task, _run_task(task)):
                done[c.key] = o
            if progress is not None:
                progress(len(done), n)
    else:
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor, as_completed

        with ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn")) as pool:
            futures = {pool.submit(_run_task, task): task for task in tasks(all_cases)}
            for f in as_completed(futures):
                for c, o in zip(futures[f], f.result()):
                    done[c.key] = o
                if progress is not None:
                    progress(len(done), n)
    return Matrix([done[c.key] for c in all_cases], time.perf_counter() - t0, workers)
