"""Sweeps over many runs on the compiled batch engine: packed batches, executors (local or
dask.distributed), Monte-Carlo over sea realisations and robustness maps over model
parameters. Tuning (:mod:`steerlab.tuning`) evaluates its populations with the same pieces.
"""
