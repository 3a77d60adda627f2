"""Standard manoeuvring trials (turning circle, zig-zag, spiral and reversed spiral, pull-out)
and the IMO manoeuvrability criteria, on any ship of the registry.

A trial is a *manoeuvre program*: a numba kernel with the controller signature
``update(z, p, t, x, ref, h) -> delta_cmd`` (:mod:`steerlab.trials.program`), run by the same
compiled closed-loop engine as the autopilots, followed by the analysis of the recorded
:class:`~steerlab.sim.result.Result` (one module per trial).
"""
