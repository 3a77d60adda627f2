"""The command layer's checks around scenario design: refusals, warnings, and a last-resort guard.

:func:`design_guard` is a safety net, not the fix: the real fixes are the bounds of the
scenario schema and the checks of the design functions (each an ``InputError`` naming its
field). Should a design still fail with an unexpected exception (``ZeroDivisionError``,
``LinAlgError``, ...), the command prints one line naming the stage and exits 2 instead of
a traceback. Only the design stage is guarded; library code raises as it does.
"""

from __future__ import annotations

import contextlib
import warnings as _warnings

from steerlab.errors import InertSettingWarning, InputError


@contextlib.contextmanager
def design_guard(stage: str = "scenario design"):
    """Turn an unexpected exception inside the block into an :class:`InputError` naming ``stage``."""
    try:
        yield
    except InputError:
        raise
    except Exception as err:  # noqa: BLE001 - the last-resort net of the CLI (see the module docstring)
        raise InputError(stage, f"failed with {type(err).__name__}: {err}; the scenario's values are outside "
                                "what the design can handle (please report it if they are sensible)") from None


def warn(lines) -> None:
    """Print each warning as one ``steerlab: warning: ...`` line on stderr (each once per command)."""
    from steerlab.messages import print_warning

    for line in lines:
        print_warning(line)


def design_checked(scenario, max_memory: float | None = None, ignore: tuple[str, ...] = ()):
    """``(setup, warnings)``: the scenario refused if impossible, built under :func:`design_guard`,
    its warnings printed (see :mod:`steerlab.sim.sanity`; with the settings its models do not
    feel, :class:`~steerlab.errors.InertSettingWarning`); refused first if its set-up would not fit
    in memory (``max_memory`` [GB], :mod:`steerlab.resources`). ``ignore``: field prefixes
    (``"controller."``) whose warnings do not concern the command (``steerlab sea`` draws the sea,
    not the autopilot's answer to it)."""
    from steerlab.sim.sanity import check_scenario, scenario_warnings
    from steerlab.sim.setup import build

    from steerlab.resources import check_setup_memory

    check_setup_memory(scenario, max_memory)  # before build() allocates the disturbance sequence
    with design_guard(), _warnings.catch_warnings(record=True) as caught:
        _warnings.simplefilter("always", InertSettingWarning)
        check_scenario(scenario)
        setup = build(scenario)
        warnings = scenario_warnings(scenario)
    for w in caught:          # a setting the models do not feel (InertSettingWarning): listed too
        if issubclass(w.category, InertSettingWarning):
            warnings.append(str(w.message))
        else:
            _warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    warnings = [w for w in warnings if not w.startswith(ignore)] if ignore else warnings
    warn(warnings)
    return setup, warnings
