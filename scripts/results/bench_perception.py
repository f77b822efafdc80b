"""The perception benchmark: cameras, sonars and the DVL's beams on one core, and what a
camera adds to a run (benchmarks/bench_perception.py)."""

from __future__ import annotations

from _common import benchmark_result, producer_cli

if __name__ == "__main__":
    producer_cli(__doc__)
    benchmark_result(
        "bench_perception",
        "Perception benchmark",
        "bench_perception.py",
        [],
        "CPU time of one process, best of interleaved rounds, one BLAS thread (absolute "
        "times depend on the machine and its load; the ratios are the run's own).",
    )
