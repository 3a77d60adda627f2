"""The optimisers: scipy differential evolution, pymoo GA and pymoo NSGA-II, resumable.

No optimiser is written here; each library's own algorithm runs and every generation's
whole population is evaluated by one call of the
:class:`~steerlab.tuning.evaluator.PopulationEvaluator` (one compiled batch of
population x conditions):

``de``
    :func:`scipy.optimize.differential_evolution` with ``vectorized=True`` (the objective
    receives the whole population), ``updating="deferred"``, ``polish=False`` and a seeded
    :class:`numpy.random.Generator`. ``pop_size`` is the total population (scipy's
    ``popsize`` is per parameter: ``ceil(pop_size / d)``).
``ga``
    :class:`pymoo.algorithms.soo.nonconvex.ga.GA` (the genetic algorithm Witkowska &
    Smierzchalski tune with), ask-and-tell.
``nsga2``
    :class:`pymoo.algorithms.moo.nsga2.NSGA2` for two or more cost expressions: the Pareto
    front (e.g. ITAE against rudder travel).

Checkpoints. After every generation the state is written atomically (temporary file +
``os.replace``) to the checkpoint file, if one was given: for pymoo the pickled algorithm
object (its population and random state), for DE the population, its costs and the state
of the random generator. A resumed run continues bit-identically to an uninterrupted one
(same generations, same best, same history and simulation count): for DE the checkpoint
holds scipy's solver state (unit-scaled population, energies, feasibility, evaluation
count, the sample index it shuffles in place) and the random state after the generation,
restored into a fresh solver, so nothing is evaluated twice. A DE checkpoint of the earlier
format is refused. A checkpoint stores the problem
it belongs to (scenario, controller, parameters, bounds, costs, conditions, method, seed)
and refuses to resume another. Checkpoints are pickles: load only your own.
"""

from __future__ import annotations

import math
import os
import pickle
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from steerlab.errors import InputError
from steerlab.progress import bar_message

METHODS = ("de", "ga", "nsga2")
CHECKPOINT_VERSION = 1


@dataclass
class TuningResult:
    method: str
    names: list
    x: np.ndarray                    # best parameters (d,) (nsga2: the front's first member)
    f: np.ndarray                    # its objectives (n_obj,)
    history: list = field(default_factory=list)   # per generation: dict
    front_x: np.ndarray | None = None  # nsga2: (k, d)
    front_f: np.ndarray | None = None  # nsga2: (k, n_obj)
    n_generations: int = 0
    n_sims: int = 0
    resumed_from: int | None = None


def _module_attr(module: str, name: str):
    import importlib

    return getattr(importlib.import_module(module), name)


class _Pickler(pickle.Pickler):
    """Pickles decorated module-level functions by reference.

    pymoo wraps some operator functions in a decorator without ``functools.wraps`` (a local
    ``wrapper``), which plain pickle refuses; such a wrapper is stored as "the attribute of
    the wrapped function's module with the wrapped function's name" when that attribute is
    the very object.
    """

    def reducer_override(self, obj):
        import importlib
        import types

        if isinstance(obj, types.FunctionType) and "<locals>" in obj.__qualname__ and obj.__closure__:
            for cell in obj.__closure__:
                inner = cell.cell_contents
                if isinstance(inner, types.FunctionType):
                    try:
                        mod = importlib.import_module(inner.__module__)
                    except ImportError:
                        continue
                    if getattr(mod, inner.__name__, None) is obj:
                        return _module_attr, (inner.__module__, inner.__name__)
        return NotImplemented


def _atomic_pickle(obj, path: Path) -> None:
    """Write ``obj`` to ``path`` whole: a temporary sibling, then ``os.replace``; the temporary
    file is removed on any failure (and a killed writer's is removed by :func:`load_checkpoint`)."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    try:
        with open(tmp, "wb") as fh:
            _Pickler(fh, protocol=pickle.HIGHEST_PROTOCOL).dump(obj)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def _remove_stale_temporaries(path: Path) -> None:
    """Delete ``.NAME.tmp-PID`` siblings of ``path`` left by processes that are gone."""
    from steerlab.outputs import _leftovers, _pid_alive

    for pid, tmp in _leftovers(path.parent, path.name, ".tmp-").items():
        if not _pid_alive(pid):
            tmp.unlink(missing_ok=True)


def _checkpoint_folder(path) -> None:
    """Create the checkpoint's folder before the first generation, as ``--out`` does its own:
    ``--checkpoint out/tune.ckpt`` on a fresh clone (no ``out/`` yet) failed when the first
    generation's checkpoint was written. A folder that cannot be made is the input error."""
    from steerlab.outputs import make_folder

    make_folder(Path(path).parent, "--checkpoint", "its folder ")


def load_checkpoint(path, problem_key: dict) -> dict | None:
    """The checkpoint at ``path`` if it exists and belongs to ``problem_key`` (else InputError)."""
    p = Path(path)
    _remove_stale_temporaries(p)
    if not p.exists():
        return None
    try:
        with open(p, "rb") as fh:
            ck = pickle.load(fh)
    except Exception as err:
        raise InputError("--checkpoint", f"cannot read checkpoint {str(p)!r}: {err}") from None
    if not isinstance(ck, dict) or ck.get("version") != CHECKPOINT_VERSION \
            or (ck.get("key", {}).get("method") == "de" and "solver" not in ck):
        raise InputError("--checkpoint", f"{str(p)!r} is not a steerlab tuning checkpoint")
    if ck.get("key") != problem_key:
        diff = sorted(k for k in set(problem_key) | set(ck.get("key", {}))
                      if problem_key.get(k) != ck.get("key", {}).get(k))
        raise InputError("--checkpoint", f"{str(p)!r} belongs to another tuning problem "
                                         f"(differs in: {', '.join(diff)}); use another file or remove it")
    return ck


class _Progress:
    def __init__(self, progress, n_gen: int, names):
        self.say = progress or (lambda msg: None)
        self.n_gen = n_gen
        self.names = names

    def __call__(self, gen: int, n_sims: int, best_f, best_x) -> None:
        params = ", ".join(f"{n}={v:.4g}" for n, v in zip(self.names, best_x))
        best = ", ".join(f"{v:.6g}" for v in np.atleast_1d(best_f))
        self.say(bar_message(gen, self.n_gen, f"gen {gen}/{self.n_gen}  sims {n_sims}  best {best}  ({params})"))


CHECKPOINT_MODES = ("auto", "resume", "fresh")
"""What an existing checkpoint does (``steerlab tune --resume`` / ``--fresh``; neither: auto):
auto and resume continue from it (resume also refuses a missing file), fresh starts over and
overwrites it. A checkpoint that already holds ``generations`` generations is finished: its
result is reported as it is, without another generation (:func:`checkpoint_plan`)."""


def checkpoint_plan(ck: dict | None, generations: int, path, mode: str = "auto") -> str:
    """One line saying what the run does with its checkpoint ``ck`` (None: none read).

    Raises :class:`InputError` on ``--resume`` without a checkpoint file and on a checkpoint
    already past ``generations`` (its result is not that of ``generations`` generations).
    """
    if mode not in CHECKPOINT_MODES:
        raise InputError("--resume", f"checkpoint mode must be one of {CHECKPOINT_MODES}, got {mode!r}")
    shown = str(path)
    if mode == "fresh":
        return f"starting fresh: {shown!r} is overwritten after the first generation (--fresh)"
    if ck is None:
        if mode == "resume":
            raise InputError("--resume", f"no checkpoint at {shown!r} to resume; run without --resume to start one")
        return f"no checkpoint at {shown!r} yet: starting, one written after every generation"
    done = int(ck["generation"])
    if done > generations:
        raise InputError("--generations", f"the checkpoint {shown!r} already holds {done} generations, more "
                                          f"than the {generations} asked; ask for {done} or more, or use --fresh")
    if done == generations:
        return (f"the checkpoint {shown!r} is finished ({done} of {generations} generations): reporting its "
                "result without another generation (--fresh starts over)")
    return f"resuming from generation {done} of {generations} in {shown!r}"


def run_optimiser(evaluator, method: str, generations: int, pop_size: int, seed: int,
                  checkpoint=None, problem_key: dict | None = None, progress=None,
                  checkpoint_mode: str = "auto") -> TuningResult:
    """Run ``method`` on ``evaluator`` (see the module docstring); ``checkpoint_mode`` is one of
    :data:`CHECKPOINT_MODES`."""
    if method not in METHODS:
        raise InputError("--method", f"must be one of {METHODS}, got {method!r}")
    if not (1 <= generations <= 100_000):
        raise InputError("--generations", f"must be in [1, 100000], got {generations}")
    if not (5 <= pop_size <= 100_000):
        raise InputError("--pop-size", f"must be in [5, 100000], got {pop_size}")
    n_obj = len(evaluator.costs)
    if method == "nsga2" and n_obj < 2:
        raise InputError("--cost", "nsga2 needs two or more cost expressions (repeat --cost)")
    if method != "nsga2" and n_obj != 1:
        raise InputError("--cost", f"method {method!r} takes exactly one cost expression, got {n_obj}")
    key = dict(problem_key or {}, method=method, seed=seed, pop_size=pop_size)
    ck = None
    if checkpoint:
        _checkpoint_folder(checkpoint)
        ck = load_checkpoint(checkpoint, key) if checkpoint_mode != "fresh" else None
        (progress or (lambda msg: None))(checkpoint_plan(ck, generations, checkpoint, checkpoint_mode))
    elif checkpoint_mode == "resume":
        raise InputError("--resume", "needs --checkpoint FILE (the checkpoint to resume)")
    prog = _Progress(progress, generations, evaluator.param_map.names)
    if method == "de":
        return _run_de(evaluator, generations, pop_size, seed, checkpoint, key, ck, prog)
    return _run_pymoo(evaluator, method, generations, pop_size, seed, checkpoint, key, ck, prog)


#: what a DE checkpoint keeps of scipy's ``DifferentialEvolutionSolver``: ``(checkpoint key,
#: solver attribute)``. scipy has no public way to continue a run, so private attributes are
#: among them; a scipy that keeps them differently, or is outside :data:`SCIPY_DE_TESTED`,
#: refuses ``--checkpoint`` before the first generation, in one line (a run without a
#: checkpoint uses scipy's public differential_evolution and reads none of them)
DE_SOLVER_STATE = (("population", "population"), ("population_energies", "population_energies"),
                   ("feasible", "feasible"), ("constraint_violation", "constraint_violation"),
                   ("nfev", "_nfev"), ("random_index", "_random_population_index"))


SCIPY_DE_TESTED = ((1, 15), (1, 18))
"""scipy versions whose differential-evolution solver state the checkpoint tests cover (from,
inclusive; to, exclusive): ``--checkpoint`` with ``--method de`` uses scipy's private solver
class only on these (:func:`_private_de_solver`); a run without a checkpoint uses the public
``scipy.optimize.differential_evolution`` on any scipy."""


def _private_de_solver():
    """scipy's ``DifferentialEvolutionSolver`` (a private module's class) for a checkpointed DE
    run, on the scipy versions of :data:`SCIPY_DE_TESTED` only; else one ``--checkpoint``
    InputError, before the first generation."""
    import re

    import scipy

    m = re.match(r"(\d+)\.(\d+)", scipy.__version__)
    version = (int(m.group(1)), int(m.group(2))) if m else None
    (a, b), (c, d) = SCIPY_DE_TESTED
    refuse = (f"this scipy ({scipy.__version__}) is not one whose differential evolution state steerlab's "
              f"tests cover (>={a}.{b},<{c}.{d}), so a DE checkpoint cannot be written or resumed; run "
              "without --checkpoint, or use --method ga")
    if version is None or not (SCIPY_DE_TESTED[0] <= version < SCIPY_DE_TESTED[1]):
        raise InputError("--checkpoint", refuse)
    try:
        from scipy.optimize._differentialevolution import DifferentialEvolutionSolver
    except ImportError:
        raise InputError("--checkpoint", refuse) from None
    return DifferentialEvolutionSolver


def _check_de_solver_state(solver) -> None:
    """One ``--checkpoint`` InputError if ``solver`` lacks an attribute of :data:`DE_SOLVER_STATE`."""
    missing = [attr for _, attr in DE_SOLVER_STATE if not hasattr(solver, attr)]
    if missing:
        import scipy

        raise InputError("--checkpoint", f"this scipy ({scipy.__version__}) keeps differential evolution's state "
                                         f"differently (no {', '.join(missing)}), so a DE checkpoint cannot be "
                                         "written or resumed; run without --checkpoint, or use --method ga")


def _de_solver_state(solver) -> dict:
    """The checkpoint's copy of the solver's state (:data:`DE_SOLVER_STATE`)."""
    out = {}
    for name, attr in DE_SOLVER_STATE:
        value = getattr(solver, attr)
        out[name] = value if isinstance(value, (int, np.integer)) else np.array(value, copy=True)
    return out


def _run_de(ev, generations, pop_size, seed, checkpoint, key, ck, prog) -> TuningResult:
    # With a checkpoint: scipy's own solver object (what differential_evolution builds and
    # runs), driven here so that a checkpoint holds its exact state: the unit-scaled population,
    # its energies, the feasibility arrays, the evaluation count, the in-place-shuffled sample
    # index and the random generator after the generation (on the tested scipy versions only:
    # _private_de_solver). Without: scipy's public differential_evolution, the same solver.
    solver_class = _private_de_solver() if checkpoint else None

    bounds = ev.param_map.bounds
    d = bounds.shape[0]
    rng = np.random.default_rng(seed)
    history = []
    gen0 = 0
    if ck is not None:
        history = list(ck["history"])
        gen0 = ck["generation"]
        ev.n_sims = ck["n_sims"]
    remaining = generations - gen0
    if remaining <= 0:
        return _de_result(ck, history, gen0, ev, resumed=gen0)
    state = {"gen": gen0}

    def objective(xT):
        return ev(np.asarray(xT).T)[:, 0]

    def callback(intermediate_result):
        state["gen"] += 1
        solver = state.get("solver")
        energies = np.asarray(intermediate_result.population_energies)
        best_x = np.asarray(intermediate_result.x, dtype=float)
        best_f = float(intermediate_result.fun)
        history.append({"generation": state["gen"], "n_sims": ev.n_sims, "best": best_f,
                        "mean": float(np.mean(energies)), **ev.param_map.values_dict(best_x)})
        prog(state["gen"], ev.n_sims, best_f, best_x)
        state["last"] = {"version": CHECKPOINT_VERSION, "key": key, "generation": state["gen"],
                         "population": np.asarray(intermediate_result.population), "energies": energies,
                         "solver": _de_solver_state(solver) if checkpoint else None,
                         "rng_state": rng.bit_generator.state,
                         "history": history, "n_sims": ev.n_sims, "best_x": best_x, "best_f": best_f}
        if checkpoint:
            _atomic_pickle(state["last"], checkpoint)

    popsize = max(2, int(math.ceil(pop_size / d)))
    options = dict(vectorized=True, updating="deferred", polish=False, rng=rng, popsize=popsize,
                   maxiter=remaining, init="latinhypercube", tol=0.0, atol=0.0, callback=callback)
    if solver_class is None:
        from scipy.optimize import differential_evolution

        differential_evolution(objective, bounds, **options)
        return _de_result(state.get("last", ck), history, state["gen"], ev, resumed=gen0 or None)
    with solver_class(objective, bounds, **options) as solver:
        state["solver"] = solver
        if checkpoint:
            _check_de_solver_state(solver)
        if ck is not None:                   # continue exactly where the checkpoint's generation ended
            saved = ck["solver"]
            for name, attr in DE_SOLVER_STATE:     # (the sample index is shuffled in place each draw)
                setattr(solver, attr, saved[name] if name == "nfev" else saved[name].copy())
            rng.bit_generator.state = ck["rng_state"]
        solver.solve()
    return _de_result(state.get("last", ck), history, state["gen"], ev, resumed=gen0 or None)


def _de_result(last, history, gen, ev, resumed) -> TuningResult:
    return TuningResult("de", list(ev.param_map.names), np.asarray(last["best_x"]),
                        np.array([last["best_f"]]), history, n_generations=gen, n_sims=ev.n_sims,
                        resumed_from=resumed)


def _run_pymoo(ev, method, generations, pop_size, seed, checkpoint, key, ck, prog) -> TuningResult:
    from pymoo.core.evaluator import Evaluator
    from pymoo.core.problem import Problem
    from pymoo.problems.static import StaticProblem

    bounds = ev.param_map.bounds
    n_obj = len(ev.costs)
    problem = Problem(n_var=bounds.shape[0], n_obj=n_obj, xl=bounds[:, 0].copy(), xu=bounds[:, 1].copy())
    resumed = None
    if ck is not None:
        from pymoo.termination.max_gen import MaximumGenerationTermination

        algorithm = ck["algorithm"]
        algorithm.termination = MaximumGenerationTermination(generations)
        history = list(ck["history"])
        ev.n_sims = ck["n_sims"]
        resumed = ck["generation"]
    else:
        if method == "ga":
            from pymoo.algorithms.soo.nonconvex.ga import GA

            algorithm = GA(pop_size=pop_size, eliminate_duplicates=True)
        else:
            from pymoo.algorithms.moo.nsga2 import NSGA2

            algorithm = NSGA2(pop_size=pop_size)
        algorithm.setup(problem, termination=("n_gen", generations), seed=seed, verbose=False)
        history = []
    gen = resumed or 0
    # a finished checkpoint (as many generations as asked) is reported as it is: pymoo's
    # has_next() would otherwise grant the restored algorithm one more generation
    while gen < generations and algorithm.has_next():
        pop = algorithm.ask()
        F = ev(pop.get("X"))
        Evaluator().eval(StaticProblem(problem, F=F), pop)
        algorithm.tell(infills=pop)
        gen += 1
        opt = algorithm.opt
        OF = opt.get("F")
        OX = opt.get("X")
        k = int(np.argmin(OF[:, 0]))
        row = {"generation": gen, "n_sims": ev.n_sims}
        if n_obj == 1:
            row.update(best=float(OF[k, 0]), mean=float(np.mean(F[:, 0])), **ev.param_map.values_dict(OX[k]))
        else:
            row.update(front_size=int(len(OF)),
                       **{f"min_f{j}": float(np.min(OF[:, j])) for j in range(n_obj)})
        history.append(row)
        prog(gen, ev.n_sims, OF[k], OX[k])
        if checkpoint:
            _atomic_pickle({"version": CHECKPOINT_VERSION, "key": key, "generation": gen,
                            "algorithm": algorithm, "history": history, "n_sims": ev.n_sims}, checkpoint)
    res = algorithm.result()
    X = np.atleast_2d(res.X)
    F = np.atleast_2d(res.F)
    if method == "ga":
        return TuningResult(method, list(ev.param_map.names), X[0], F[0], history, n_generations=gen,
                            n_sims=ev.n_sims, resumed_from=resumed)
    order = np.argsort(F[:, 0], kind="stable")
    X, F = X[order], F[order]
    return TuningResult(method, list(ev.param_map.names), X[0], F[0], history, X, F, gen,
                        ev.n_sims, resumed)
