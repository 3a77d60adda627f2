"""Where packed batches run: this machine's cores (default) or a dask.distributed cluster.

``LocalExecutor`` runs the whole batch in one call of the compiled batch engine (vectorised
groups of runs over a pool of threads on the local cores). ``DaskExecutor`` cuts the batch into chunks of ``chunk_size`` runs
(:meth:`~steerlab.sim.batch.PackedBatch.take`: each chunk carries only the disturbance
sequences it uses), sends them to the workers of a dask.distributed cluster, and
concatenates the outputs in the original order. Runs are independent and deterministic, so
the numbers are bit-identical to the local run for the same seeds (tested with a
``LocalCluster`` on loopback). Workers need steerlab importable (same version).

``make_executor(spec)``: ``None`` or ``""`` -> local; ``"local"`` -> a ``LocalCluster`` on
127.0.0.1 started for this process; anything else -> the address of a running scheduler,
e.g. ``tcp://10.0.0.5:8786``. dask is an optional extra (``pip install steerlab[dask]``).

A local cluster whose start fails (a worker process that dies while it starts: distributed's
"Nanny failed to start", a timeout) is closed and started again, up to
:data:`CLUSTER_START_ATTEMPTS` times, with one warning line per retry; if every attempt fails
the command stops with one ``--dask`` line, never a traceback.
"""

from __future__ import annotations

import numpy as np

from steerlab.errors import InputError
from steerlab.sim.batch import BatchResult, PackedBatch


def _run_chunk(chunk: PackedBatch, record_every):
    return chunk.run(record_every)


class LocalExecutor:
    """One compiled call on this machine."""

    name = "local"

    def run(self, batch: PackedBatch, record_every: int | None = None, progress=None) -> BatchResult:
        """``progress(done, n)``: runs done so far (see :meth:`PackedBatch.run`)."""
        return batch.run(record_every, progress)

    def close(self) -> None:
        pass


class DaskExecutor:
    """Chunks of the batch on a dask.distributed cluster (``client``: a ``distributed.Client``)."""

    def __init__(self, client, chunk_size: int = 256, cluster=None):
        if chunk_size < 1:
            raise InputError("--chunk-size", f"must be >= 1, got {chunk_size}")
        self.client = client
        self.chunk_size = int(chunk_size)
        self._cluster = cluster
        self.name = f"dask ({client.scheduler.address})"

    def run(self, batch: PackedBatch, record_every: int | None = None, progress=None) -> BatchResult:
        """``progress(done, n)``: runs done so far, after each chunk that comes back."""
        from distributed import as_completed

        n = batch.n
        bounds = list(range(0, n, self.chunk_size)) + [n]
        chunks = [batch.take(np.arange(a, b)) for a, b in zip(bounds[:-1], bounds[1:])]
        futures = self.client.map(_run_chunk, chunks, [record_every] * len(chunks), pure=False)
        if progress is not None:
            size = {f.key: c.n for f, c in zip(futures, chunks)}
            done = 0
            for f in as_completed(futures):
                done += size[f.key]
                progress(done, n)
        return BatchResult.concatenate(self.client.gather(futures))

    def close(self) -> None:
        self.client.close()
        if self._cluster is not None:
            self._cluster.close()


CLUSTER_START_ATTEMPTS = 3
"""Starts of a local dask cluster tried before giving up (:func:`start_local_cluster`)."""


def _why(err: BaseException) -> str:
    text = " ".join(str(err).split()) or type(err).__name__
    return f"{type(err).__name__}: {text}" if type(err).__name__ not in text else text


def start_local_cluster(local_workers: int = 2, attempts: int = CLUSTER_START_ATTEMPTS, cluster_class=None,
                        client_class=None):
    """A started ``distributed.LocalCluster`` on 127.0.0.1 and its ``Client``.

    A start that fails (a worker process dying while it starts, a timeout) is retried with a
    fresh cluster, saying so in one warning line; after ``attempts`` failures one
    :class:`InputError` on ``--dask`` (the CLI's one line, exit 2). ``cluster_class`` and
    ``client_class`` default to distributed's ``LocalCluster`` and ``Client``.
    """
    if client_class is None:
        from distributed import Client as client_class

    from steerlab.messages import print_warning

    if cluster_class is None:
        from distributed import LocalCluster as cluster_class
    why = ""
    for attempt in range(1, attempts + 1):
        cluster = None
        try:
            cluster = cluster_class(n_workers=local_workers, threads_per_worker=1, processes=True,
                                    host="127.0.0.1", dashboard_address=None)
            return cluster, client_class(cluster)
        except Exception as err:          # noqa: BLE001 - any failure of a start is retried, then one line
            why = _why(err)
            if cluster is not None:
                try:
                    cluster.close()
                except Exception:         # noqa: BLE001 - a half-started cluster may not close cleanly
                    pass
            if attempt < attempts:
                print_warning(f"--dask local: the cluster did not start ({why}); starting it again "
                              f"(attempt {attempt + 1} of {attempts})")
    raise InputError("--dask", f"the local cluster did not start in {attempts} attempts (last: {why}); run "
                               "without --dask, or check the machine's memory and process limits")


def make_executor(spec: str | None, chunk_size: int = 256, local_workers: int = 2):
    """An executor for ``--dask SPEC`` (see the module docstring)."""
    if not spec:
        return LocalExecutor()
    try:
        from distributed import Client
    except ImportError:  # pragma: no cover - optional extra
        raise InputError("--dask", "needs the optional extra: pip install 'steerlab[dask]'") from None
    if spec == "local":
        cluster, client = start_local_cluster(local_workers)
        return DaskExecutor(client, chunk_size, cluster)
    if "://" not in spec and ":" not in spec:
        raise InputError("--dask", f"must be 'local' or a scheduler address like tcp://HOST:8786, got {spec!r}")
    try:
        client = Client(spec, timeout=10)
    except (OSError, TimeoutError) as err:
        raise InputError("--dask", f"cannot reach the scheduler at {spec!r}: {err}") from None
    return DaskExecutor(client, chunk_size)
