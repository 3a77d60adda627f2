"""A local dask cluster whose start fails (a worker process that dies while it starts) is
started again, saying so in one line; when every attempt fails the command stops with one
``--dask`` line, never distributed's "Nanny failed to start" traceback (issue 35)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from steerlab.errors import InputError
from steerlab.sweeps.executors import start_local_cluster

pytest.importorskip("distributed")


class _Cluster:
    """Stands in for ``distributed.LocalCluster``: fails its first ``failures`` starts as a
    nanny whose worker died does."""

    starts = 0

    def __init__(self, failures):
        self.failures = failures

    def __call__(self, **kwargs):
        _Cluster.starts += 1
        if _Cluster.starts <= self.failures:
            raise RuntimeError("Nanny failed to start.")
        return self


def test_a_failed_start_is_retried_with_one_warning_line_each(capsys):
    _Cluster.starts = 0
    cluster, client = start_local_cluster(2, attempts=3, cluster_class=_Cluster(2), client_class=lambda c: ("client", c))
    assert client == ("client", cluster)
    err = capsys.readouterr().err.strip().splitlines()
    assert _Cluster.starts == 3 and len(err) == 2
    assert all(line.startswith("steerlab: warning: --dask local: the cluster did not start (RuntimeError: Nanny "
                               "failed to start.); starting it again") for line in err)


def test_every_start_failing_is_one_dask_line():
    _Cluster.starts = 0
    with pytest.raises(InputError, match=r"the local cluster did not start in 2 attempts \(last: RuntimeError: "
                                         r"Nanny failed to start\.\)") as exc:
        start_local_cluster(2, attempts=2, cluster_class=_Cluster(5), client_class=lambda c: c)
    assert exc.value.field == "--dask" and _Cluster.starts == 2


@pytest.mark.slow
@pytest.mark.skipif(os.name != "posix", reason="a worker process that exits while it starts")
def test_a_real_worker_dying_at_start_is_retried(tmp_path):
    """Real processes: a dask preload makes the first worker to start exit at once (os._exit);
    the cluster starts on the second attempt, one warning line, no traceback."""
    preload = tmp_path / "die_once.py"
    preload.write_text(textwrap.dedent("""
        import os
        def dask_setup(worker):
            try:
                fd = os.open(os.environ["STEERLAB_TEST_DIE_ONCE"], os.O_CREAT | os.O_EXCL | os.O_WRONLY)
            except FileExistsError:
                return
            os.close(fd)
            os._exit(1)
    """))
    env = dict(os.environ, STEERLAB_TEST_DIE_ONCE=str(tmp_path / "died"),
               DASK_DISTRIBUTED__WORKER__PRELOAD=f'["{preload}"]')
    code = ("from steerlab.sweeps.executors import make_executor\n"
            "ex = make_executor('local'); print('started', ex.name.startswith('dask (tcp://127.0.0.1:')); ex.close()")
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0 and p.stdout.strip() == "started True", (p.stdout, p.stderr)
    assert (tmp_path / "died").exists()                      # a worker did die at start
    assert "Traceback" not in p.stderr
    warnings = [ln for ln in p.stderr.splitlines() if ln.startswith("steerlab: warning: --dask local")]
    assert len(warnings) == 1 and "Nanny failed to start" in warnings[0], p.stderr
