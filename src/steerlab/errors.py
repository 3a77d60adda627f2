"""The one exception type for bad user input."""

from typing import Any


class InputError(ValueError):
    """Bad input: names the offending field and the allowed range.

    The CLI turns it into a one-line message and exit code 2, with nothing written to
    the output directory.
    """

    def __init__(self, field: str, message: str):
        self.field = field
        self.message = message
        super().__init__(f"{field}: {message}")


def require_finite_range(field: str, value: Any, lo: float | None = None, hi: float | None = None,
                         lo_open: bool = False, hi_open: bool = False) -> float:
    """Raise :class:`InputError` unless ``value`` is a finite number within the range."""
    import math

    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(field, f"must be a number, got {value!r}") from None
    lo_s = "-inf" if lo is None else repr(lo)
    hi_s = "inf" if hi is None else repr(hi)
    rng = f"{'(' if lo_open or lo is None else '['}{lo_s}, {hi_s}{')' if hi_open or hi is None else ']'}"
    if not math.isfinite(v):
        raise InputError(field, f"must be finite, got {v!r}; allowed range {rng}")
    if lo is not None and (v < lo or (lo_open and v == lo)):
        raise InputError(field, f"{v!r} is out of range; allowed range {rng}")
    if hi is not None and (v > hi or (hi_open and v == hi)):
        raise InputError(field, f"{v!r} is out of range; allowed range {rng}")
    return v


class DivergedError(RuntimeError):
    """A run whose state left the finite numbers (or whose ship spun away from its reference).

    The CLI prints it as one line and exits with code 3 (:data:`EXIT_DIVERGED`); no metrics
    are reported for it. ``time`` [s] is when it happened, ``what`` the state or check,
    ``hint`` the likely cause.
    """

    def __init__(self, time: float | None, what: str, hint: str):
        self.time = time
        self.what = what
        self.hint = hint
        at = "" if time is None else f" at t = {time:g} s"
        super().__init__(f"the run diverged{at} ({what}); {hint}")


class InertSettingWarning(UserWarning):
    """A setting the run's models do not feel, e.g. a wind on a ship without a wind model.

    The run goes on as it would without the setting (the scenario stays valid: the same wind
    still drives the sea report and the time series' wind columns); the message names the
    setting, why it has no effect and what would give it one. The CLI prints it as one line
    ``steerlab: warning: ...`` on stderr.
    """


EXIT_BAD_INPUT = 2      #: bad input: one line naming the field (InputError)
EXIT_DIVERGED = 3       #: the run diverged or the ship spun (DivergedError)
