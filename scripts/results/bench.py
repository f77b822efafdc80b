"""The dynamics benchmark: costs as ratios to one rigid-body pin.aba call."""

from __future__ import annotations

from _common import benchmark_result, producer_cli

if __name__ == "__main__":
    producer_cli(__doc__)
    benchmark_result(
        "bench",
        "Dynamics benchmark",
        "bench_dynamics.py",
        [],
        "Timed in one process; the ratios are the numbers to compare across machines "
        "(absolute times depend on the machine and its load).",
    )
