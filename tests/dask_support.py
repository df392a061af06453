"""Faults injected into a Dask cluster by the tests (a worker process killed while it runs a task)."""

from __future__ import annotations

import os
import signal
import time


def kill_a_busy_worker(client, state: dict, wait_s: float = 10.0) -> None:
    """SIGKILL the process of a worker that is running a task (once: ``state["killed"]`` names it after), waiting
    up to ``wait_s`` for one to be busy."""
    if state.get("killed"):
        return
    t0 = time.time()
    while time.time() - t0 < wait_s:
        busy = [w for w, keys in client.processing().items() if keys]
        if busy:
            pids = client.run(os.getpid, workers=[busy[0]])
            os.kill(pids[busy[0]], signal.SIGKILL)
            state["killed"] = busy[0]
            return
        time.sleep(0.05)
