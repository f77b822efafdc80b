"""Reading a study file into a `Study`, checked: every mistake is found before any run starts
and raised as `StudyError` naming the file and the entry
(``parameter[2] 'environment.stiffness_N_m'``); the base scenario is loaded with each
parameter at its extremes, so every run's scenario is known to load."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from uvms_pin.apps.study.spec import (
    APPLY_MODES,
    DISTRIBUTIONS,
    PLANT_FACTORS,
    PLANT_PREFIX,
    Parameter,
    Run,
    Study,
    lookup,
)
from uvms_pin.checks import check_memory
from uvms_pin.errors import ScenarioError, StudyError
from uvms_pin.scenario.overrides import KEY_PATH, parse_key_path
from uvms_pin.scenario.schema import Table, is_number
from uvms_pin.scenario.toml import read_toml

# ---- parsing ------------------------------------------------------------------------------


def load_study(path: str | Path) -> Study:
    """Read and check a study file; every run's scenario is known to load afterwards.

    Raises:
        StudyError: naming the file and the entry (missing base, unknown parameter path,
            empty range, unknown distribution, a value the scenario rejects, ...).
    """
    path = Path(path)
    source = str(path)
    raw = read_toml(path, StudyError)
    unknown = set(raw) - {"study", "fixed", "parameter", "report"}
    if unknown:
        raise StudyError(f"{source}: unknown table(s): {', '.join(sorted(unknown))}")
    top = Table(raw, "", source, error=StudyError)
    head = top.table_or_empty("study")
    name = head.string("name", path.stem)
    description = head.string("description", "")
    base_entry = head.string("base")
    seed = head.seed("seed", None)
    samples = head.integer("samples", 1, minimum=1)
    head.finish()
    if not base_entry.strip():
        raise head.error("base", "is empty; give the base scenario's file")
    base = (path.parent / base_entry).resolve()
    if not base.is_file():
        raise head.error("base", f"scenario '{base_entry}' not found ({base})")
    base_raw = read_toml(base, StudyError, f"{source}: study.base: '{base_entry}'")
    fixed = _fixed(raw.get("fixed", {}), source)
    entries = top.tables("parameter")
    if not entries:
        raise StudyError(f"{source}: needs at least one [[parameter]]")
    parameters = tuple(_parameter(entry, k, base_raw, fixed) for k, entry in enumerate(entries))
    seen = set()
    for p in parameters:
        if p.path in seen:
            raise StudyError(f"{source}: {p.entry}: the path is given twice")
        seen.add(p.path)
    _check_size(source, parameters, samples, fixed)
    report = raw.get("report", {})
    if not isinstance(report, dict):
        raise StudyError(f"{source}: [report] must be a table")
    _check_report(report, source, {p.path for p in parameters})
    study = Study(name, description, path, base, seed, samples, fixed, parameters, report, base_raw)
    _check_against_base(study, source)
    return study


#: memory of one grid value (a float in a tuple, and the array it came from) [bytes]
_GRID_POINT_BYTES = 48
#: memory of one run of a study (its `Run` of a few dicts, its table row, the scheduler's
#: record of it) [bytes], plus per parameter or fixed entry: estimates on the high side
_RUN_BYTES = 8192
_RUN_ENTRY_BYTES = 512


def _check_size(
    source: str, parameters: tuple[Parameter, ...], samples: int, fixed: dict[str, Any]
) -> None:
    """StudyError before the run list is made if the study's runs would not fit in memory."""
    grids = [len(p.grid) for p in parameters if p.grid is not None]
    n_runs = math.prod(grids) * samples
    shape = " x ".join([*(f"{n} points" for n in grids), f"{samples} samples"])
    check_memory(
        n_runs * (_RUN_BYTES + _RUN_ENTRY_BYTES * (len(parameters) + len(fixed))),
        f"{source}: the study's {n_runs} runs ({shape}), their list and table,",
        "give fewer grid points or samples, or split the study",
        StudyError,
    )


def _fixed(table: Any, source: str) -> dict[str, Any]:
    """[fixed]: dotted scenario keys applied to every run (no plant factor)."""
    if not isinstance(table, dict):
        raise StudyError(f"{source}: [fixed] must be a table of dotted keys")
    fixed = _flatten(table)
    for key in fixed:
        if key.startswith(PLANT_PREFIX):
            raise StudyError(f"{source}: fixed.{key}: plant factors go in a [[parameter]]")
    return fixed


def _flatten(table: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in table.items():
        dotted = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(_flatten(value, dotted + "."))
        else:
            out[dotted] = value
    return out


def _parameter(t: Table, k: int, base_raw: dict[str, Any], fixed: dict[str, Any]) -> Parameter:
    """One [[parameter]]: where it goes, how it is applied, its grid or its distribution."""
    path = t.string("path")
    t.label = f"parameter[{k}] '{path}'"
    if KEY_PATH.match(path) is None:
        raise t.fail("not a dotted key like 'environment.stiffness_N_m' or 'a.b[2]'")
    apply = t.string("apply", "set", APPLY_MODES)
    _check_target(t, path, apply, base_raw, fixed)
    kinds = [name for name in (*_GRIDS, "distribution") if t.has(name)]
    if len(kinds) != 1:
        raise t.fail("give exactly one of values, linspace, logspace, distribution")
    if kinds[0] == "distribution":
        distribution, args = _distribution(t)
        grid = None
    else:
        distribution, args = None, {}
        grid = _GRIDS[kinds[0]](t)
        if _value_kind(grid[0]) != "number" and (apply != "set" or path.startswith(PLANT_PREFIX)):
            what = "a plant factor" if path.startswith(PLANT_PREFIX) else f"apply = '{apply}'"
            raise t.fail(f"values: {what} needs numbers, got {grid[0]!r}")
    t.finish()
    return Parameter(path, t.label, apply, grid, distribution, args)


def _check_target(
    t: Table, path: str, apply: str, base_raw: dict[str, Any], fixed: dict[str, Any]
) -> None:
    """A plant factor uvms-pin knows, or a scenario key whose base value fits ``apply``."""
    key, index = parse_key_path(path).key, parse_key_path(path).index
    if path.startswith(PLANT_PREFIX):
        if path[len(PLANT_PREFIX) :] not in PLANT_FACTORS or index is not None:
            known = ", ".join(PLANT_PREFIX + f for f in PLANT_FACTORS)
            raise t.fail(f"unknown plant factor; known: {known}")
        return
    base_value = fixed.get(key, lookup(base_raw, key, None))
    if index is not None:
        if not isinstance(base_value, list):
            raise t.fail(f"'{key}' is not a list in the base scenario, it cannot be indexed")
        if int(index) >= len(base_value):
            raise t.fail(f"index {index} out of range: '{key}' has {len(base_value)} entries")
    elif apply != "set" and base_value is None:
        raise t.fail(f"apply = '{apply}' needs a value of '{key}' in the base scenario")


def _values(t: Table) -> tuple[Any, ...]:
    """A listed grid: numbers (or lists of numbers), or booleans, or strings (one kind per
    parameter: a table column holds one type); the latter two only set a key."""
    values = t.pop_raw("values")
    if not isinstance(values, list) or not values:
        raise t.fail("values: the list is empty")
    kind = _value_kind(values[0])
    for v in values:
        if _value_kind(v) is None:
            raise t.fail(
                f"values: {v!r} is not a finite number, a list of numbers, a boolean or a string"
            )
        if _value_kind(v) != kind:
            raise t.fail(f"values: {values!r} mixes kinds: give numbers, booleans or strings")
    return tuple(values)


def _value_kind(value: Any) -> str | None:
    """ "number" (a finite number or a non-empty list of them), "boolean", "string" or None."""
    if is_number(value) or (isinstance(value, list) and value and all(map(is_number, value))):
        return "number"
    if isinstance(value, bool):
        return "boolean"
    return "string" if isinstance(value, str) else None


def _spaced(kind: str):
    """A grid of ``count`` points from ``start`` to ``stop``, evenly (linspace) or
    geometrically (logspace) spaced: ``[start, stop, count]``."""

    def read(t: Table) -> tuple[float, ...]:
        spec = t.pop_raw(kind)
        if (
            not isinstance(spec, list)
            or len(spec) != 3
            or not all(is_number(x) for x in spec[:2])
            or isinstance(spec[2], bool)
            or not isinstance(spec[2], int)
        ):
            raise t.fail(f"{kind}: must be [start, stop, count], got {spec!r}")
        start, stop, count = spec
        if count < 1:
            raise t.fail(f"{kind}: empty range (count = {count})")
        check_memory(count * _GRID_POINT_BYTES, f"{kind}: {count} points", "give fewer", t.fail)
        if count > 1 and start == stop:
            raise t.fail(f"{kind}: empty range (start = stop = {start})")
        if kind == "logspace" and (start <= 0 or stop <= 0):
            raise t.fail(f"logspace: start and stop must be > 0, got {start}, {stop}")
        space = np.geomspace if kind == "logspace" else np.linspace
        return tuple(float(x) for x in space(start, stop, count))

    return read


#: grid key -> how the grid is read from a [[parameter]]
_GRIDS = {"values": _values, "linspace": _spaced("linspace"), "logspace": _spaced("logspace")}


def _distribution(t: Table) -> tuple[str, dict[str, float]]:
    """The random law of a [[parameter]] and its arguments, checked."""
    distribution = t.pop_raw("distribution")
    if distribution not in DISTRIBUTIONS:
        raise t.fail(f"unknown distribution {distribution!r}; known: {', '.join(DISTRIBUTIONS)}")
    normal = distribution == "normal"
    needed = ("mean", "std") if normal else ("low", "high")
    args: dict[str, float] = {}
    for name in (*needed, *(("low", "high") if normal else ())):
        if t.has(name):
            args[name] = t.number(name)
        elif name in needed:
            raise t.fail(f"distribution '{distribution}' needs '{name}'")
    if normal and args["std"] <= 0:
        raise t.fail(f"std must be > 0, got {args['std']}")
    if args.get("low", -math.inf) >= args.get("high", math.inf):
        raise t.fail(f"empty range: low = {args['low']} >= high = {args['high']}")
    if distribution == "log-uniform" and args["low"] <= 0:
        raise t.fail(f"log-uniform needs low > 0, got {args['low']}")
    return distribution, args


def _check_report(report: dict[str, Any], source: str, paths: set[str]) -> None:
    known = {"heatmaps", "metrics"}
    unknown = set(report) - known
    if unknown:
        raise StudyError(f"{source}: [report] has unknown key(s): {', '.join(sorted(unknown))}")
    heatmaps = report.get("heatmaps", [])
    if not isinstance(heatmaps, list):
        raise StudyError(f"{source}: report.heatmaps: must be a list of parameter-path pairs")
    for k, pair in enumerate(heatmaps):
        texts = isinstance(pair, list) and all(isinstance(p, str) for p in pair)
        if not (texts and len(pair) == 2 and set(pair) <= paths):
            raise StudyError(
                f"{source}: report.heatmaps[{k}]: must be two parameter paths, got {pair!r}"
            )
    metrics = report.get("metrics", [])
    if not isinstance(metrics, list) or not all(isinstance(m, str) for m in metrics):
        raise StudyError(f"{source}: report.metrics: must be a list of metric names")


# ---- checks against the base scenario (before any run) ------------------------------------


def _extremes(study: Study, runs: list[Run]) -> dict[str, list[Any]]:
    """Per parameter, the distinct values to try: min and max if numeric, else all."""
    out: dict[str, list[Any]] = {}
    for p in study.parameters:
        values = [r.values[p.path] for r in runs]
        if all(is_number(v) for v in values):
            bounds = [p.args[k] for k in ("low", "high") if k in p.args]  # the support
            out[p.path] = sorted({min(values), max(values), *bounds})
        else:
            distinct = {json.dumps(v): v for v in values}
            out[p.path] = list(distinct.values())
    return out


def _check_against_base(study: Study, source: str) -> None:
    """Load the base scenario with the fixed overrides; then with each parameter alone at
    each of its extremes over the runs (so a failure names its entry); then with the first
    run's overrides as a whole. Plant factors are checked for sign."""
    from uvms_pin.scenario.load import load_scenario

    try:
        load_scenario(study.base, study.fixed)
    except ScenarioError as exc:
        raise StudyError(f"{source}: study.base with [fixed]: {exc}") from exc
    for p in study.parameters:  # plant factors: the whole support, not only the draws
        if p.is_plant and p.distribution is not None:
            lowest = p.args.get("low", -math.inf)
            if p.apply == "add":
                lowest += 1.0
            name = p.path[len(PLANT_PREFIX) :]
            bad = lowest <= 0 if name == "mass_scale" else lowest < 0
            if bad:
                limit = "> 0" if name == "mass_scale" else ">= 0"
                raise StudyError(
                    f"{source}: {p.entry}: the factor must be {limit} over the whole "
                    f"distribution (give a low bound), its lowest value is {lowest}"
                )
    runs = study.runs()
    first = runs[0]
    extremes = _extremes(study, runs)
    for p in study.parameters:
        for value in extremes[p.path]:
            values = dict(first.values)
            values[p.path] = value
            overrides, plant = study.resolve(values)
            if p.is_plant:
                name = p.path[len(PLANT_PREFIX) :]
                bad = plant[name] <= 0 if name == "mass_scale" else plant[name] < 0
                if bad:
                    limit = "> 0" if name == "mass_scale" else ">= 0"
                    raise StudyError(
                        f"{source}: {p.entry}: the factor must be {limit}, got {plant[name]}"
                    )
                continue
            alone = dict(study.fixed)
            alone[p.key] = overrides[p.key]
            try:
                load_scenario(study.base, alone)
            except ScenarioError as exc:
                raise StudyError(f"{source}: {p.entry} = {value!r}: {exc}") from exc
    try:
        load_scenario(study.base, first.overrides)
    except ScenarioError as exc:
        raise StudyError(f"{source}: the first run's parameters together: {exc}") from exc
