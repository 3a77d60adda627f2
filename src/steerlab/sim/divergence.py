r"""Finite-state and spin checks of finished runs: a diverged run is never reported as good.

The engines integrate whatever they are given; a model driven outside its validity range or
integrated with too large a step can leave the finite numbers (NaN/inf), after which every
metric is meaningless. These checks look at a run's outputs only (the compiled loops are not
touched), so they cost one pass over the log of a single run and one over the final states
and on-line accumulators of a batch:

* :func:`check_run` (single runs, both engines): the first non-finite sample of the log
  (time and state) raises :class:`~steerlab.errors.DivergedError`; so does a *spin*, the
  heading leaving its reference by more than a full turn,
  ``max_t |unwrap(psi - psi_ref)| > 2 pi`` (a closed loop that is unstable on this ship: the
  heading error wraps, so its metrics would look bounded). A spin that began before the first
  non-finite sample is the one reported (the cause), with the time the state overflowed;
* :func:`diverged_rows` (batches): a run whose final state or on-line accumulator is not
  finite. Sweeps treat such runs as failed (no metrics, infinite cost).
"""

from __future__ import annotations

import math
from typing import Optional

import numpy as np

from steerlab.errors import DivergedError
from steerlab.units import KNOT
from steerlab.ships.state import IU

SPIN_LIMIT = 2.0 * math.pi   #: heading away from its reference by more than this [rad]: a spin


def diverged_rows(final_states, acc=None) -> np.ndarray:
    """Boolean (n,): runs whose final state (or on-line accumulator) has a NaN or an inf."""
    bad = ~np.all(np.isfinite(np.asarray(final_states)), axis=1)
    if acc is not None:
        bad |= ~np.all(np.isfinite(np.asarray(acc)), axis=1)
    return bad


def likely_cause(setup) -> str:
    """A hint naming the scenario's speed against the ship's validity range and its step."""
    lo, hi = setup.ship.speed_range
    speed = float(setup.x0[IU]) if setup.x0.shape[0] > IU else math.nan
    parts = []
    if math.isfinite(speed) and not (lo <= speed <= hi):
        parts.append(f"the speed {speed / KNOT:.3g} kn is outside the validity range of {setup.ship.name!r}: "
                     f"{lo / KNOT:.3g}-{hi / KNOT:.3g} kn")
    parts.append(f"dt = {setup.dt:g} s may be too large for the model (try a smaller dt)")
    return "likely cause: " + "; or ".join(parts)


def divergence(result, setup=None) -> Optional[DivergedError]:
    """The :class:`DivergedError` of ``result`` if it left the finite numbers or spun, else None.

    ``setup`` (the run's :class:`~steerlab.sim.setup.SimSetup`, optional) makes the hint of a
    non-finite run name its speed against the ship's validity range (:func:`likely_cause`).
    """
    X = result.states
    bad = ~np.isfinite(X)
    first_bad = int(np.argmax(bad.any(axis=1))) if bad.any() else X.shape[0]
    # a spin among the finite samples comes first: a ship that spun for minutes before its
    # state overflowed diverged because the loop is unstable, not because of the step
    off = np.abs(np.unwrap(result.psi[:first_bad] - result.psi_ref[:first_bad]))
    if off.size and float(off.max()) > SPIN_LIMIT:
        k = int(np.argmax(off > SPIN_LIMIT))
        later = (f" (its state left the finite numbers at t = {float(result.time[first_bad]):g} s)"
                 if first_bad < X.shape[0] else "")
        return DivergedError(float(result.time[k]), "the ship spun: its heading left the reference by more "
                             f"than a full turn{later}", "the closed loop is unstable: the controller does not "
                             "suit this ship (check its design model and gains); for open-loop turns use "
                             "'steerlab trial'" + (f"; or {likely_cause(setup)[len('likely cause: '):]}"
                                                  if later and setup is not None else ""))
    if first_bad < X.shape[0]:
        k, j = first_bad, int(np.argmax(bad[first_bad]))
        name = result.state_names[j] if j < len(result.state_names) else f"state {j}"
        hint = likely_cause(setup) if setup is not None else ("likely cause: a speed outside the ship's "
                                                                "validity range, or a dt too large for the model")
        return DivergedError(float(result.time[k]), f"{name} = {float(X[k, j])!r}", hint)
    return None


def check_run(result, setup) -> None:
    """Raise :class:`DivergedError` if ``result`` (of ``setup``) left the finite numbers or spun."""
    err = divergence(result, setup)
    if err is not None:
        raise err
