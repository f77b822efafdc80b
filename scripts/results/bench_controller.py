"""The prescribed-performance controller's cost per compute: ratios to one pin.aba call."""

from __future__ import annotations

from _common import benchmark_result, producer_cli

if __name__ == "__main__":
    producer_cli(__doc__)
    benchmark_result(
        "bench_controller",
        "Controller benchmark",
        "bench_controller.py",
        [],
        "Process CPU time, best of interleaved rounds; the ratio to one `pin.aba` call is the number to compare across machines.",
    )
