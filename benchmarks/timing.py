"""Timing shared by the benchmarks: best of interleaved rounds, in this process's CPU time.

Every benchmark reports ratios of such times (to one ``pin.aba`` call, to MuJoCo), never
absolute figures to assert on.
"""

from __future__ import annotations

import argparse
import math
import time
import timeit
from collections.abc import Callable, Hashable
from pathlib import Path

from threadpoolctl import threadpool_limits


def one_blas_thread() -> threadpool_limits:
    """Limit BLAS (and OpenMP) pools to one thread for the rest of the process.

    numpy's OpenBLAS keeps its worker threads spinning for a while after a call; on a 2-core
    machine they take CPU time that ``time.process_time`` (all threads) then counts against
    whatever is timed next, e.g. a compiled call timed after a numpy one. Small matrices
    never gain from BLAS threads, so the Python reference loses nothing.
    """
    return threadpool_limits(limits=1)


def best_times(
    cases: dict[Hashable, Callable[[], object]], repeat: int, batch_s: float = 0.05
) -> dict[Hashable, float]:
    """Best time per call [s] of each case over ``repeat`` rounds.

    Times are this process's CPU time (``time.process_time``: what other processes take
    from a shared machine is not counted). Each case is called once first (a first call may
    build caches), then each round times every case once, in a batch of about ``batch_s``:
    short batches interleaved over many rounds let the minimum find the machine's quiet
    moments for every case alike.
    """
    timers = {name: timeit.Timer(fn, timer=time.process_time) for name, fn in cases.items()}
    for fn in cases.values():
        fn()
    numbers = {name: max(1, round(batch_s / timer.timeit(1))) for name, timer in timers.items()}
    best = dict.fromkeys(cases, math.inf)
    for _ in range(repeat):
        for name, timer in timers.items():
            seconds = timer.timeit(numbers[name]) / numbers[name]
            best[name] = min(best[name], seconds)
    return best


def bench_arguments(doc: str) -> argparse.Namespace:
    """A benchmark's command line: ``--repeat N`` (rounds, 15) and ``--json FILE``; ``doc``
    its module docstring (the first line is the help's description)."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--json", type=Path)
    return parser.parse_args()
