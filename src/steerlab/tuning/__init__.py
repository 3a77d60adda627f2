"""Optimiser-based tuning on the compiled batch engine (``steerlab tune``).

:mod:`~steerlab.costs` (safe cost expressions over the metrics),
:mod:`~steerlab.tuning.params` (parameter names -> packed controller records, by name in the
record's declared layout, through the wrappers), :mod:`~steerlab.tuning.evaluator` (a whole population x
conditions per compiled call), :mod:`~steerlab.tuning.optimisers` (scipy DE, pymoo GA and
NSGA-II, checkpoints) and :mod:`~steerlab.tuning.session` (one job end to end). See
docs/tuning.md.
"""
