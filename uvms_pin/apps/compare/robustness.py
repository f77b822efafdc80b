"""``compare-controllers --robustness``: every controller over a small set of perturbed cases,
run through the study runner (`uvms_pin.apps.study.runner`, Dask; resumable like any study).

Cases (each alone, the rest nominal): nominal; environment stiffness x10; plant inertial and
hydrodynamic parameters (mass, added mass, damping, buoyancy, so the vehicle stays as
buoyant as designed) x1.3 and x0.7; sensor noise x5 (every ``sensors.*_noise*`` key the
scenario sets); disturbance amplitude x5. The controllers never see the factors: a
baseline's model (computed_torque) stays the nominal one.
"""

from __future__ import annotations

import copy
import functools
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from uvms_pin.apps.compare.metrics import COLUMNS, Criteria
from uvms_pin.apps.compare.table import _text
from uvms_pin.apps.study.execute import batch_rows
from uvms_pin.apps.study.plant import modify_plant
from uvms_pin.apps.study.runner import load_results, run_study
from uvms_pin.apps.study.spec import PLANT_FACTORS, Run, Study, run_id
from uvms_pin.errors import ScenarioError
from uvms_pin.results.atomic import write_text_atomic
from uvms_pin.scenario.overrides import apply_overrides
from uvms_pin.scenario.toml import read_toml

__all__ = ["CASES", "robustness_cases", "run_robustness"]

CASES = ("nominal", "stiffness_x10", "plant_x1.3", "plant_x0.7", "noise_x5", "disturbance_x5")


def _scaled(raw: dict[str, Any], table: str, key: str, factor: float) -> dict[str, Any]:
    value = (raw.get(table) or {}).get(key)
    if value is None:
        return {}
    scaled = (np.asarray(value, dtype=float) * factor).tolist()
    return {f"{table}.{key}": scaled}


def robustness_cases(raw: dict[str, Any]) -> dict[str, tuple[dict[str, Any], dict[str, float]]]:
    """case -> (scenario overrides, plant factors) for the scenario document ``raw``."""
    noise = {}
    for key in raw.get("sensors") or {}:
        if "noise" in key:
            noise.update(_scaled(raw, "sensors", key, 5.0))
    plant = {s: dict.fromkeys(PLANT_FACTORS, s) for s in (1.3, 0.7)}
    return {
        "nominal": ({}, {}),
        "stiffness_x10": (_scaled(raw, "environment", "stiffness_N_m", 10.0), {}),
        "plant_x1.3": ({}, plant[1.3]),
        "plant_x0.7": ({}, plant[0.7]),
        "noise_x5": (noise, {}),
        "disturbance_x5": (_scaled(raw, "disturbance", "amplitude", 5.0), {}),
    }


@dataclass
class _CaseStudy(Study):
    """A study whose runs are the given controller x case list (not a grid of a file)."""

    case_runs: list[Run] = field(default_factory=list)

    def runs(self) -> list[Run]:
        return self.case_runs


def execute_case(base: str, run: Run, rollout_dir: str | None, criteria: Criteria) -> dict:
    """One controller on one case: the comparison row (never raises; errors go in the row)."""
    return execute_cases(base, [run], rollout_dir, criteria)[0]


def execute_cases(
    base: str, runs: list[Run], rollout_dir: str | None, criteria: Criteria
) -> list[dict]:
    """`execute_case` of each of ``runs``, their scenarios built one by one and simulated
    together (`uvms_pin.sim.batch.run_batch`, one thread: a study's worker is one process of
    one thread); the rows in order, each the row of the run alone, its wall time its build
    plus its simulation."""
    from uvms_pin.apps.compare.runs import batch_run_row

    def fill(row: dict, scenario, outcome, run: Run) -> None:
        compared, _ = batch_run_row(run.values["controller"], scenario, outcome, criteria)
        compared.pop("controller")
        row.update(compared)  # status "ok" or "stopped" (the reason says why)

    return batch_rows(runs, lambda row, run: _case_scenario(base, run), fill)


def _case_scenario(base: str, run: Run):
    """The scenario of one controller on one case."""
    from uvms_pin.scenario.baselines import baseline_controller_table
    from uvms_pin.scenario.load import scenario_from_dict

    raw = apply_overrides(read_toml(Path(base), ScenarioError), run.overrides)
    variant = {k: v for k, v in raw.items() if k != "baselines"}
    variant["controller"] = baseline_controller_table(raw, run.values["controller"])
    return modify_plant(scenario_from_dict(variant, base), run.plant)


def run_robustness(
    scenario_path: Path,
    controllers: list[str],
    out: Path,
    criteria: Criteria,
    workers: int,
    overrides: dict[str, Any] | None = None,
) -> list[dict[str, Any]]:
    """Run every controller x case into ``out`` (a study directory); the rows.

    ``overrides`` (the command's ``--set``) apply to every run, before the case's own."""
    scenario_path = Path(scenario_path)
    user = dict(overrides or {})
    raw = apply_overrides(read_toml(scenario_path, ScenarioError), user)
    cases = robustness_cases(raw)
    out.mkdir(parents=True, exist_ok=True)
    spec = out / "robustness.toml"
    write_text_atomic(
        spec,
        f'[study]\nname = "robustness"\nbase = "{scenario_path.resolve()}"\n'
        f"controllers = {controllers!r}\ncases = {list(cases)!r}\n"
        f"after_s = {criteria.after_s!r}\nband_N = {criteria.band_N!r}\n"
        f"tolerance_N = {criteria.tolerance_N!r}\n".replace("'", '"'),
    )
    runs = []
    for name in controllers:
        for case, (overrides, plant) in cases.items():
            values = {"controller": name, "case": case}
            seed = int((raw.get("scenario") or {}).get("seed", 0))
            factors = {**dict.fromkeys(PLANT_FACTORS, 1.0), **plant}
            overrides = {**copy.deepcopy(user), **copy.deepcopy(overrides), "scenario.seed": seed}
            runs.append(Run(run_id(values, seed), len(runs), 0, seed, values, overrides, factors))
    study = _CaseStudy("robustness", "", spec, scenario_path.resolve(), 0, 1, {}, (), {}, raw, runs)
    run_fn = functools.partial(execute_case, criteria=criteria)
    batch_fn = functools.partial(execute_cases, criteria=criteria)
    run_study(study, out, workers=workers, progress=False, run_fn=run_fn, batch_fn=batch_fn)
    table = load_results(out)
    return table.sort_values("run_index").to_dict("records")


def robustness_table(rows: list[dict[str, Any]]) -> str:
    """Markdown: one line per controller, per case the force error RMS and held or not."""
    cases = list(dict.fromkeys(r["case"] for r in rows))
    lines = ["| controller | " + " | ".join(cases) + " |", "|---|" + "---|" * len(cases)]
    for name in dict.fromkeys(r["controller"] for r in rows):
        cells = []
        for case in cases:
            r = next(x for x in rows if x["controller"] == name and x["case"] == case)
            if r["status"] in ("error", "stopped"):
                cells.append(r["status"])  # the CSV's reason / error column says why
                continue
            verdict = "holds" if r.get("success") else "fails"
            cells.append(f"{_text(float(r['force_error_rms_N']))} N, {verdict}")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_robustness(rows: list[dict[str, Any]], out: Path) -> list[Path]:
    """``robustness.csv`` (every column of every row) and ``robustness.md``."""
    import pandas as pd

    columns = ["controller", "case", "status", "error"] + [c for c in COLUMNS if c != "controller"]
    frame = pd.DataFrame(rows).reindex(columns=columns)
    return [
        write_text_atomic(out / "robustness.csv", frame.to_csv(index=False)),
        write_text_atomic(out / "robustness.md", robustness_table(rows)),
    ]
