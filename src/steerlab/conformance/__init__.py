"""The conformance matrix: does every law steer every catalogue ship, or say why not (issue 30).

Every catalogue ship at its design speed and at both ends of its speed range
(:mod:`~steerlab.conformance.points`) x every built-in controller with its default settings
x calm water and a JONSWAP sea of sea state 5 (:mod:`~steerlab.conformance.cases`): a 20 deg
course change, judged **steers** (settles within 1 deg and stays, rudder reversals bounded),
**refused** (the design raised one line naming a field) or **fails** with the reason
(:mod:`~steerlab.conformance.judge`). :func:`run_matrix` runs it
(:mod:`~steerlab.conformance.matrix`), :mod:`~steerlab.conformance.table` writes it as
Markdown (docs/conformance.md, ``steerlab conformance``).

The random-plants check (Nomoto models designed from ``(K, T)`` alone, a plant in plain
NumPy) is :mod:`~steerlab.conformance.plants`.
"""

from steerlab.conformance.matrix import TARGET, Matrix, Outcome, run_matrix  # noqa: F401

__all__ = ["TARGET", "Matrix", "Outcome", "run_matrix"]
