"""Result of a run: time series with fixed axes, names and units; CSV / Parquet export."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Optional

import numpy as np

from steerlab.angles import wrap_to_pi_array
from steerlab.environment.channels import CHANNEL_NAMES, CHANNEL_UNITS

if TYPE_CHECKING:
    import pandas

    from steerlab.errors import DivergedError


@dataclass
class Result:
    """One run. Axis 0 of every array is time (``n_steps + 1`` rows, ``t_k = k dt``).

    Attributes
    ----------
    time : (N,) [s]
    states : (N, nx) plant states, columns ``state_names`` (last column: rudder angle delta)
    delta_cmd : (N,) rudder order held over step k [rad]
    psi_ref, r_ref : (N,) reference heading [rad] and rate [rad/s]
    disturbance : (N, n_channels) see :mod:`steerlab.environment.channels`
    """

    time: np.ndarray
    states: np.ndarray
    state_names: tuple
    state_units: tuple
    delta_cmd: np.ndarray
    psi_ref: np.ndarray
    r_ref: np.ndarray
    disturbance: np.ndarray
    meta: dict = field(default_factory=dict)

    def col(self, name: str) -> np.ndarray:
        return self.states[:, self.state_names.index(name)]

    @property
    def psi(self) -> np.ndarray:
        return self.col("psi")

    @property
    def r(self) -> np.ndarray:
        return self.col("r")

    @property
    def delta(self) -> np.ndarray:
        return self.col("delta")

    @property
    def heading_error(self) -> np.ndarray:
        """``wrap_to_pi(psi_ref - psi)`` [rad]."""
        return wrap_to_pi_array(self.psi_ref - self.psi)

    def divergence(self) -> Optional[DivergedError]:
        """Why this run cannot be reported, or None: a :class:`~steerlab.errors.DivergedError` if
        a state left the finite numbers, or if the ship *spun* (its heading left the reference
        by more than a full turn, ``max |unwrap(psi - psi_ref)| > 2 pi``: an unstable closed
        loop, whose wrapped heading error would make the metrics look bounded). The check the
        CLI makes before it reports a run (exit 3); ``simulate`` returns such runs as they are
        (an open-loop turn spins on purpose). ``raise r.divergence()`` if it is not None."""
        from steerlab.sim.divergence import divergence

        return divergence(self)

    @property
    def dt(self) -> float:
        return float(self.time[1] - self.time[0]) if len(self.time) > 1 else math.nan

    def columns(self) -> dict:
        """Flat column dict ``name [unit] -> array`` in export order."""
        cols = {"time [s]": self.time}
        for n, u, c in zip(self.state_names, self.state_units, self.states.T):
            cols[f"{n} [{u}]"] = c
        cols["delta_cmd [rad]"] = self.delta_cmd
        cols["psi_ref [rad]"] = self.psi_ref
        cols["r_ref [rad/s]"] = self.r_ref
        for n, u, c in zip(CHANNEL_NAMES, CHANNEL_UNITS, self.disturbance.T):
            cols[f"{n} [{u}]"] = c
        return cols

    def to_pandas(self) -> pandas.DataFrame:
        """A ``pandas.DataFrame``: index ``time [s]``, columns ``name [unit]`` as in :meth:`columns`."""
        from steerlab.sim.frames import result_frame

        return result_frame(self)

    def to_csv(self, path: str | os.PathLike[str], progress: Optional[Callable[[int, int], None]] = None) -> Path:
        """Write the columns of :meth:`columns` as CSV (``%.10g``, one header line).

        The bytes are those of ``numpy.savetxt(..., fmt="%.10g")``, written by the compiled
        formatter of :mod:`steerlab.fast_csv` (several times faster; ``progress(rows_done,
        rows)`` after each block of rows).
        """
        from steerlab.fast_csv import write_csv

        cols = self.columns()
        return write_csv(path, list(cols), list(cols.values()), progress)   # stacked block by block

    def to_parquet(self, path: str | os.PathLike[str]) -> Path:
        """Write Parquet (needs the optional ``pyarrow``)."""
        try:
            import pyarrow.parquet as pq
        except ImportError as err:  # pragma: no cover - depends on the environment
            raise RuntimeError("Parquet export needs pyarrow: pip install 'steerlab[parquet]'") from err
        from steerlab.arrow_table import arrow_table

        path = Path(path)
        pq.write_table(arrow_table({k: np.asarray(v) for k, v in self.columns().items()}), path)
        return path
