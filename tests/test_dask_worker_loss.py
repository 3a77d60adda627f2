"""A real dask.distributed cluster (a scheduler and two worker processes on loopback) loses a
worker to SIGKILL in the middle of a Monte-Carlo sweep: the scheduler runs the lost chunks
again on the survivor (and the nanny's restarted worker), and every number is identical to
the serial run (steerlab.sweeps.executors)."""

from __future__ import annotations

import os
import signal

import numpy as np
import pytest

from conftest import make_scenario
from steerlab.sweeps.executors import DaskExecutor, LocalExecutor
from steerlab.sweeps.montecarlo import run_montecarlo


@pytest.mark.slow
@pytest.mark.skipif(os.name != "posix", reason="SIGKILL of a worker process")
def test_a_worker_killed_mid_sweep_changes_no_number():
    distributed = pytest.importorskip("distributed")
    sc = make_scenario(duration=200.0, seed=5, environment={"waves": True},
                       guidance={"psi0_deg": 0.0, "changes": [{"t": 20.0, "psi_deg": 10.0}]})
    n = 12
    serial = run_montecarlo(sc, n, record_every=5, executor=LocalExecutor())
    killed = {}

    class KillingExecutor(DaskExecutor):
        """Kills one worker process (SIGKILL) when the first chunk comes back."""

        def run(self, batch, record_every=None, progress=None):
            def on_progress(done, total):
                if not killed:
                    pids = self.client.run(os.getpid)                       # {worker address: pid}
                    addr, pid = sorted(pids.items())[-1]
                    os.kill(pid, signal.SIGKILL)
                    killed.update(address=addr, pid=pid, done=done, total=total)
                if progress is not None:
                    progress(done, total)

            return super().run(batch, record_every, on_progress)

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        remote = run_montecarlo(sc, n, record_every=5, executor=KillingExecutor(client, chunk_size=1))
        alive = set(client.run(os.getpid).values())
    assert killed["pid"] not in alive                                        # that worker really died
    assert killed and killed["done"] < killed["total"], killed               # it died mid-sweep
    for k in serial.per_run:
        np.testing.assert_array_equal(remote.per_run[k], serial.per_run[k], err_msg=k)
    for p in serial.error_bands_deg:
        np.testing.assert_array_equal(remote.error_bands_deg[p], serial.error_bands_deg[p])
        np.testing.assert_array_equal(remote.rudder_bands_deg[p], serial.rudder_bands_deg[p])
    assert remote.stats == serial.stats and not remote.diverged.any()
