"""A SIGTERM while the local Dask cluster starts (1 to 5 s at the start of every multi-chunk run) is deferred,
not discarded: it is raised once the start is over (it used to raise inside Dask's start-up: 29 to 48 lines of
tracebacks), and the half-started cluster is closed. The cluster is a stand-in that signals this process while
it "starts", so the test is exact about the timing; a real cluster is started by tests/test_cli_errors.py."""

import os
import signal
import time

import pytest

from ccproof.scale import engine


class _Stopped(Exception):
    pass


@pytest.fixture
def fake_cluster(monkeypatch):
    import distributed

    log = []

    class Cluster:
        def __init__(self, *a, **k):
            os.kill(os.getpid(), log[0])  # the signal arrives in the middle of the start
            time.sleep(0.2)
            log.append("started")  # the start ran to its end

        def close(self):
            log.append("closed")

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.close()

    class Client(Cluster):
        def __init__(self, *a, **k):
            log.append("client")

    monkeypatch.setattr(distributed, "LocalCluster", Cluster)
    monkeypatch.setattr(distributed, "Client", Client)
    return log


def test_sigterm_during_the_cluster_start_is_raised_after_it(fake_cluster, monkeypatch):
    def stop(signum, frame):
        raise _Stopped

    previous = signal.signal(signal.SIGTERM, stop)
    try:
        fake_cluster.append(signal.SIGTERM)
        with pytest.raises(_Stopped), engine.client_for("local:2"):
            pytest.fail("the run went on after SIGTERM")
        assert fake_cluster[1] == "started" and "closed" in fake_cluster
        assert signal.getsignal(signal.SIGTERM) is stop
    finally:
        signal.signal(signal.SIGTERM, previous)
