"""Regenerate every table and figure the documentation quotes (``make results``).

    python scripts/make_results.py [--only NAME ...] [--skip NAME ...] [--list]

Each result is one script in scripts/results/ writing docs/results/<name>.md (and its
figures into docs/). To add a result, add its script there and its name to PRODUCERS.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# name -> what it regenerates (the script is scripts/results/<name>.py); in run order
PRODUCERS = {
    "paper": "the paper's scenario: docs/results/paper.md, docs/paper_force.png",
    "realistic": "the realistic scenario: docs/results/realistic.md, docs/realistic_force.png",
    "robustness": "robustness table: docs/results/robustness.md",
    "station_keeping": "your own controller (a PD): docs/results/station_keeping.md",
    "bench": "benchmark table: docs/results/bench.md",
    "bench_mujoco": "uvms-pin vs MuJoCo: docs/results/bench_mujoco.md",
    "bench_controller": "controller benchmark: docs/results/bench_controller.md",
    "bench_gym": "Gymnasium step rate: docs/results/bench_gym.md",
    "compare_arms": "arm comparison: docs/results/compare_arms.md, docs/arm_comparison.png",
    "compare_controllers": (
        "controller comparison: docs/results/compare_controllers.md, docs/controllers_force.png"
    ),
    "study_model_uncertainty": "study summary: docs/results/study_model_uncertainty.md",
    "study_paper_claims": "study summary: docs/results/study_paper_claims.md",
    "bluerov_force": "BlueROV2 + Alpha 5 force task: docs/results/bluerov_force.md, docs/bluerov_alpha5_force.png",
    "pool_validation": "pool trials vs simulator: docs/results/pool_validation.md, docs/pool_*.png",
    "identification": "hull parameters fitted to the pool trials: docs/results/identification.md, docs/identified_alt_002-0.png, docs/identified_alt_002-1.png",
    "sea_state": "the sea-state scenario: docs/results/sea_state.md, docs/sea_state_force.png",
    "study_sea_state": "study summary: docs/results/study_sea_state.md",
    "surface": "the free surface, analytic cases and surfacing: docs/results/surface.md, docs/surfacing.png",
    "world": "the seabed landing and the cost of contacts: docs/results/world.md, docs/seabed_landing.png",
    "push_object": "a free box pushed across the seafloor: docs/results/push_object.md, docs/push_object.png",
    "contact_modes": "compliant or rigid moving contacts, scenario by scenario: docs/results/contact_modes.md",
    "derivatives": "cost of the dynamics' derivatives and of an MPC re-plan: docs/results/derivatives.md",
    "tracking": "end-effector tracking, controller x task x conditions: docs/results/tracking.md, docs/tracking_*.png",
    "estimator": "station keeping on the navigation estimate: docs/results/estimator.md, docs/estimator_station_keeping.png",
    "bench_perception": "cameras, sonars and the DVL's beams on one core: docs/results/bench_perception.md",
    "seabed_survey": "a survey with a multibeam, a sonar, a camera and a beam-cast DVL: docs/results/seabed_survey.md, docs/seabed_survey.png",
    "cooperative_transport": "two UVMS carry a bar without communication: docs/results/cooperative_transport.md, docs/cooperative_transport.png",
    "study_cooperative_share": "study summary: docs/results/study_cooperative_share.md",
    "stability": "passive models for 60 s and random actions in the environments: docs/results/stability.md",
}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", choices=list(PRODUCERS), default=None)
    parser.add_argument("--skip", nargs="+", choices=list(PRODUCERS), default=[])
    parser.add_argument("--list", action="store_true", help="list the results and exit")
    args = parser.parse_args(argv)
    if args.list:
        for name, what in PRODUCERS.items():
            print(f"{name:<26} {what}")
        return 0
    sys.path.insert(0, str(ROOT / "scripts" / "results"))
    from _common import refuse_shortened_runs

    refuse_shortened_runs()
    names = [n for n in (args.only or PRODUCERS) if n not in args.skip]
    failed = []
    for name in names:
        start = time.perf_counter()
        print(f"== {name}: {PRODUCERS[name]}", flush=True)
        script = ROOT / "scripts" / "results" / f"{name}.py"
        if subprocess.run([sys.executable, str(script)], cwd=ROOT, check=False).returncode:
            failed.append(name)
        print(f"== {name}: {time.perf_counter() - start:.0f} s", flush=True)
    if failed:
        print(f"make results: failed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
