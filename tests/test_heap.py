"""The heap policy of long runs (tqdyn.workflows.heap): large freed blocks
go back to the system instead of staying in a fragmented heap.

Reference: first principles of glibc's malloc (its documented dynamic mmap
threshold: freeing a mapped block raises the threshold to that block's
size, after which blocks of that size come from the heap, where small live
blocks above them keep the freed memory resident).  The scenario is built
so that the retained memory is known in advance: 25 blocks of 8 MB (above
the policy's 4 MiB threshold), each followed by a live 2 KB block, then
the 8 MB blocks freed -- 200 MB stay resident without the policy, none
with it.
"""

import os
import platform
import subprocess
import sys

import pytest

from tqdyn.workflows.heap import bound_heap_retention

GLIBC = sys.platform.startswith("linux") and platform.libc_ver()[0] == "glibc"

_SCRIPT = """
import sys, numpy as np
def rss():
    with open('/proc/self/statm') as f:
        return int(f.read().split()[1]) * 4096 / 1e6
if sys.argv[1] == "policy":
    from tqdyn.workflows.heap import bound_heap_retention
    assert bound_heap_retention()
a = np.ones(1 << 20)
del a                            # one mapped 8 MB block freed: glibc raises its threshold
base = rss()
big, pins = [], []
for i in range(25):
    big.append(np.ones(1 << 20))  # 8 MB
    pins.append(np.ones(256))     # 2 KB kept alive above each 8 MB block
del big
print(rss() - base)              # MB still resident of the 200 MB freed
"""


def _retained_mb(mode: str) -> float:
    # glibc's default policy: no MALLOC_* tunables (Dask's nanny puts MALLOC_TRIM_THRESHOLD_ into the
    # environment of a process that started a local cluster, and a set trim threshold turns glibc's
    # dynamic mmap threshold off)
    env = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_")}
    out = subprocess.run([sys.executable, "-c", _SCRIPT, mode], capture_output=True, text=True, check=True,
                         env=env)
    return float(out.stdout)


@pytest.mark.skipif(not GLIBC, reason="glibc's malloc only")
def test_freed_large_blocks_leave_the_resident_set():
    # measured: 0.004 MB retained with the policy, 210 MB without
    assert _retained_mb("policy") < 5.0
    assert _retained_mb("default") > 100.0  # the failure mode the policy prevents


@pytest.mark.skipif(not GLIBC, reason="glibc's malloc only")
def test_policy_takes_effect_once():
    assert bound_heap_retention() is True
    assert bound_heap_retention() is True
