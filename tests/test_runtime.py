"""Process-level memory tuning (:mod:`signorini.runtime`).

The claim of :func:`retain_freed_memory` is measured in fresh processes: after it, a large
array that is freed stays in the process (no ``munmap``), and allocating it again costs no
page faults; without it, the memory goes back to the system and the pages fault in again.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

import signorini.runtime as runtime

PROBE = """
import json, resource, sys
import numpy as np
from signorini.runtime import retain_freed_memory

def rss():
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * 4096

took = retain_freed_memory() if sys.argv[1] == "tuned" else None
a = np.ones(2**23)  # 64 MiB, far above glibc's default mmap threshold
del a
kept = rss()
faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
a = np.ones(2**23)
faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - faults
del a
print(json.dumps({"took": took, "rss_after_free": kept, "faults": faults}))
"""


def probe(mode: str) -> dict:
    out = subprocess.run(
        [sys.executable, "-c", PROBE, mode], capture_output=True, text=True, check=True
    ).stdout
    return json.loads(out)


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc and /proc only")
def test_freed_memory_is_kept_and_reused_without_page_faults():
    tuned, plain = probe("tuned"), probe("plain")
    mib = 2**20
    print(
        f"tuned: took effect {tuned['took']}, {tuned['faults']} page faults on reallocation, "
        f"RSS after free {tuned['rss_after_free'] / mib:.0f} MiB; plain: {plain['faults']} "
        f"faults, RSS after free {plain['rss_after_free'] / mib:.0f} MiB"
    )
    assert tuned["took"] is True
    # the 64 MiB stay in the tuned process and are gone from the plain one
    assert tuned["rss_after_free"] - plain["rss_after_free"] > 56 * mib
    # reallocating them: (almost) no page faults against at least one per huge page
    assert tuned["faults"] <= 8 and plain["faults"] >= 32


class FakeLibc:
    """Records ``mallopt`` calls; answers ``result``."""

    def __init__(self, result: int = 1) -> None:
        self.calls: list[tuple[int, int]] = []
        self.result = result

    def mallopt(self, param: int, value: int) -> int:
        self.calls.append((param, value))
        return self.result


def test_sets_the_mmap_and_trim_thresholds_and_one_arena(monkeypatch):
    libc = FakeLibc()
    monkeypatch.setattr(runtime.ctypes, "CDLL", lambda name: libc)
    assert runtime.retain_freed_memory() is True
    # M_MMAP_THRESHOLD = -3 to 1 GiB, M_TRIM_THRESHOLD = -1 to the largest int,
    # M_ARENA_MAX = -8 to one
    assert libc.calls == [(-3, 1 << 30), (-1, (1 << 31) - 1), (-8, 1)]


def test_reports_failure(monkeypatch):
    monkeypatch.setattr(runtime.ctypes, "CDLL", lambda name: FakeLibc(result=0))
    assert runtime.retain_freed_memory() is False

    def no_libc(name):
        raise OSError("no C library")

    monkeypatch.setattr(runtime.ctypes, "CDLL", no_libc)
    assert runtime.retain_freed_memory() is False
    monkeypatch.setattr(runtime.ctypes, "CDLL", lambda name: object())  # no mallopt
    assert runtime.retain_freed_memory() is False


THREADED = """
import json, sys, threading
import numpy as np
from signorini.runtime import retain_freed_memory

def rss():
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * 4096

retain_freed_memory()
def work():
    a = np.ones(2**23)  # 64 MiB, freed in this thread
    del a
thread = threading.Thread(target=work)
thread.start(); thread.join()
before = rss()
a = np.ones(2**23)  # in the main thread: the memory the other thread freed
print(json.dumps({"grown": rss() - before}))
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc and /proc only")
def test_memory_a_thread_freed_is_reused_by_the_main_thread():
    """One heap for every thread (``M_ARENA_MAX = 1``): what a background thread
    (:mod:`signorini.algebra.backends.beside`) freed serves the main thread's next allocation, so
    the process does not keep both threads' peaks."""
    out = subprocess.run(
        [sys.executable, "-c", THREADED], capture_output=True, text=True, check=True
    ).stdout
    grown = json.loads(out)["grown"]
    print(f"RSS grown by {grown / 2**20:.1f} MiB reallocating 64 MiB a thread freed")
    assert grown < 8 * 2**20
