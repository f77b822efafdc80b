"""Record controller inputs from real runs of both shipped scenarios, and the oracle's outputs.

    .venv/bin/python scripts/record_ppc_measurements.py [--out tests/control/data/...]

Runs ``paper_force_tracking`` (LSODA, continuous control: many calls with the funnel
extension on) and ``realistic_force_tracking`` (500 Hz, generalized pseudo-inverse and
null-space task) for a short time, captures every ``Measurement`` the controller is given
(and whether the funnel extension was on), keeps an evenly spaced subset, and stores it
with the outputs of the frozen pre-optimization controller (``tests/control/
ppc_oracle``): tau and the funnel margin. ``tests/control/test_ppc_oracle.py`` replays
the measurements through the package's controller and through the oracle.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path
from unittest import mock

import numpy as np

from uvms_pin.control.base import Controller
from uvms_pin.control.measurement import Measurement
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import Scenario, simulate

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "control"))
from ppc_oracle import in_place_of_the_package_ppc  # noqa: E402

#: scenario file stem -> simulated duration [s]
RUNS = {"paper_force_tracking": 1.0, "realistic_force_tracking": 2.0}


class _Recorder(Controller):
    """Delegates to a controller and remembers every measurement it was given."""

    def __init__(self, inner: Controller):
        self.inner = inner
        self.records: list[tuple[Measurement, bool]] = []
        self._extended = False

    def compute(self, time_s, measurement):
        self.records.append((measurement, self._extended))
        return self.inner.compute(time_s, measurement)

    def reset(self):
        self.inner.reset()

    def signals(self):
        return self.inner.signals()

    def funnel_margin(self):
        return self.inner.funnel_margin()

    def set_funnel_extension(self, enabled):
        self._extended = bool(enabled)
        self.inner.set_funnel_extension(enabled)


def oracle_controller(scenario: Scenario) -> Controller:
    """The scenario's controller, built with the same arguments by the frozen oracle."""
    with mock.patch(
        "uvms_pin.scenario.ppc.PrescribedPerformanceController", in_place_of_the_package_ppc
    ):
        return scenario.controller_factory(scenario.uvms)


def record(stem: str, duration_s: float, keep: int) -> dict[str, np.ndarray]:
    scenario = load_scenario(
        ROOT / "scenarios" / f"{stem}.toml", {"scenario.duration_s": duration_s}
    )
    recorders: list[_Recorder] = []

    def factory(uvms):
        recorders.append(_Recorder(scenario.controller_factory(uvms)))
        return recorders[-1]

    simulate(dataclasses.replace(scenario, controller_factory=factory))
    records = recorders[0].records
    chosen = np.unique(np.linspace(0, len(records) - 1, keep).round().astype(int))
    oracle = oracle_controller(scenario)
    out: dict[str, list] = {k: [] for k in ("time_s", "q", "v", "wrench_world", "extended")}
    out.update(tau=[], margin=[])
    for index in chosen:
        measurement, extended = records[index]
        oracle.set_funnel_extension(extended)
        out["tau"].append(oracle.compute(measurement.time_s, measurement).copy())
        out["margin"].append(oracle.funnel_margin())
        out["time_s"].append(measurement.time_s)
        out["q"].append(measurement.q)
        out["v"].append(measurement.v)
        out["wrench_world"].append(measurement.wrench_world)
        out["extended"].append(extended)
    print(f"{stem}: {len(records)} calls, kept {len(chosen)}, {sum(out['extended'])} extended")
    return {f"{stem}/{k}": np.asarray(v) for k, v in out.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--out", type=Path, default=ROOT / "tests" / "control" / "data" / "ppc_runs.npz"
    )
    parser.add_argument("--keep", type=int, default=300, help="measurements kept per scenario")
    args = parser.parse_args()
    arrays: dict[str, np.ndarray] = {}
    for stem, duration_s in RUNS.items():
        arrays.update(record(stem, duration_s, args.keep))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(args.out, **arrays)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
