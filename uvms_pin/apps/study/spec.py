"""Study files (TOML) -> a list of runs, each with its overrides, plant factors and seed.

A study names a base scenario and the parameters to vary. Grid parameters (``values``,
``linspace``, ``logspace``) form a Cartesian product; random parameters (``distribution``)
are drawn ``samples`` times; every grid point is run with every sample (so grid points
share their random draws: common random numbers, which makes grid comparisons sharper).

Reproducibility: from the master ``seed``, sample k draws parameter ``path`` from
``SeedSequence(seed, spawn_key=(k, crc32(path)))`` and gets its scenario seed (sensor
noise) from ``SeedSequence(seed, spawn_key=(k, SEED_KEY))``. A draw depends on nothing
else, so adding a parameter or more samples leaves the existing runs unchanged, and their
run ids (a hash of the parameter values and the seed) let a rerun skip them.

Parameter paths:

- ``plant.mass_scale``, ``plant.added_mass_scale``, ``plant.damping_scale``,
  ``plant.buoyancy_scale``: factors applied to the loaded model (see `modify_plant`);
- any dotted key of the scenario TOML (``environment.stiffness_N_m``, ``controller.k_x``,
  ...), optionally with an element index (``initial.joint_positions_rad[3]``), optionally
  ``apply = "scale"`` (times the base value) or ``"add"`` (plus the base value).

Every mistake is found before any run starts and raised as `StudyError` naming the file
and the entry (``parameter[2] 'environment.stiffness_N_m'``).
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from uvms_pin.errors import ScenarioError, UvmsPinError
from uvms_pin.scenario.overrides import KEY_PATH, parse_key_path
from uvms_pin.scenario.toml import read_toml

SEED_KEY = 0x5EED  # spawn-key component of a sample's scenario seed
PLANT_PREFIX = "plant."
PLANT_FACTORS = ("mass_scale", "added_mass_scale", "damping_scale", "buoyancy_scale")
DISTRIBUTIONS = ("uniform", "normal", "log-uniform")
APPLY_MODES = ("set", "scale", "add")


class StudyError(UvmsPinError):
    """A study file is malformed or names something the base scenario does not have."""


@dataclass(frozen=True)
class Parameter:
    """One varied quantity: where it goes, how it is applied, and its grid or distribution.

    Attributes:
        path: dotted key, optionally indexed (``initial.joint_positions_rad[3]``).
        entry: how error messages name it (``parameter[2] 'path'``).
        apply: "set", "scale" (times the base value) or "add" (plus the base value).
        grid: the values of a grid parameter, or None for a random one.
        distribution, args: the random law ("uniform": low, high; "normal": mean, std,
            optional low/high clip; "log-uniform": low, high > 0).
    """

    path: str
    entry: str
    apply: str = "set"
    grid: tuple[Any, ...] | None = None
    distribution: str | None = None
    args: dict[str, float] = field(default_factory=dict)

    @property
    def is_plant(self) -> bool:
        return self.path.startswith(PLANT_PREFIX)

    @property
    def column(self) -> str:
        """The study table's column of this parameter (see `column_name`)."""
        return column_name(self.path, self.apply)

    @property
    def key(self) -> str:
        """The scenario key without the element index."""
        return parse_key_path(self.path).key

    @property
    def index(self) -> int | None:
        return parse_key_path(self.path).index

    def draw(self, master_seed: int, sample: int) -> float:
        """This parameter's value in sample ``sample`` (independent of every other draw)."""
        ss = np.random.SeedSequence(master_seed, spawn_key=(sample, zlib.crc32(self.path.encode())))
        rng = np.random.default_rng(ss)
        a = self.args
        if self.distribution == "uniform":
            return float(rng.uniform(a["low"], a["high"]))
        if self.distribution == "log-uniform":
            return float(math.exp(rng.uniform(math.log(a["low"]), math.log(a["high"]))))
        value = float(rng.normal(a["mean"], a["std"]))
        return float(np.clip(value, a.get("low", -math.inf), a.get("high", math.inf)))


def column_name(path: str, apply: str = "set") -> str:
    """What a table column of a varied parameter holds: the value set (``path``), a factor
    on the base value (``path [x base]``) or an increment to it (``path [+ base]``): the
    column of a scaled 0.15 N amplitude holds 2.0, not newtons."""
    return {"set": path, "scale": f"{path} [x base]", "add": f"{path} [+ base]"}[apply]


@dataclass(frozen=True)
class Run:
    """One simulation of a study.

    Attributes:
        run_id: hash of the parameter values and the seed (the resume key).
        index: position in the study's run list; sample: the random-sample index.
        seed: the scenario seed (sensor noise).
        values: parameter path -> value, as varied (what the table records).
        overrides: dotted scenario keys -> values, ready for `load_scenario`.
        plant: plant factor name -> value (``mass_scale``, ...), 1.0 when not varied.
        columns: parameter path -> its table column (`column_name`).
    """

    run_id: str
    index: int
    sample: int
    seed: int
    values: dict[str, Any]
    overrides: dict[str, Any]
    plant: dict[str, float]
    columns: dict[str, str] = field(default_factory=dict)


@dataclass
class Study:
    """A parsed study file.

    Attributes:
        name, description: from [study]. path: the study file. base: the base scenario.
        seed: the master seed. samples: number of random samples per grid point.
        fixed: dotted overrides applied to every run (the [fixed] table).
        parameters: the varied quantities. report: options of the [report] table.
        base_raw: the base scenario's TOML as a dict (read once, for scale/add and indices).
    """

    name: str
    description: str
    path: Path
    base: Path
    seed: int
    samples: int
    fixed: dict[str, Any]
    parameters: tuple[Parameter, ...]
    report: dict[str, Any]
    base_raw: dict[str, Any]

    @property
    def grid_parameters(self) -> tuple[Parameter, ...]:
        return tuple(p for p in self.parameters if p.grid is not None)

    @property
    def random_parameters(self) -> tuple[Parameter, ...]:
        return tuple(p for p in self.parameters if p.grid is None)

    def runs(self) -> list[Run]:
        """Every run: each grid point (outer, in file order) times each sample (inner)."""
        grids = [p.grid for p in self.grid_parameters]
        out: list[Run] = []
        for point in itertools.product(*grids):
            for sample in range(self.samples):
                values = dict(zip((p.path for p in self.grid_parameters), point, strict=True))
                for p in self.random_parameters:
                    values[p.path] = p.draw(self.seed, sample)
                values = {p.path: values[p.path] for p in self.parameters}  # file order
                seed = sample_seed(self.seed, sample)
                overrides, plant = self.resolve(values)
                overrides["scenario.seed"] = seed
                columns = {p.path: p.column for p in self.parameters}
                out.append(
                    Run(
                        run_id(values, seed),
                        len(out),
                        sample,
                        seed,
                        values,
                        overrides,
                        plant,
                        columns,
                    )
                )
        return out

    def resolve(self, values: dict[str, Any]) -> tuple[dict[str, Any], dict[str, float]]:
        """Parameter values -> (scenario overrides, plant factors)."""
        overrides = copy.deepcopy(self.fixed)
        plant = dict.fromkeys(PLANT_FACTORS, 1.0)
        for p in self.parameters:
            value = values[p.path]
            if p.is_plant:
                name = p.path[len(PLANT_PREFIX) :]
                plant[name] = _combine(plant[name], value, p.apply)
                continue
            key, index = p.key, p.index
            current = overrides[key] if key in overrides else _lookup(self.base_raw, key, None)
            if index is None:
                overrides[key] = _combine(current, value, p.apply)
            else:
                items = list(current)
                items[index] = _combine(items[index], value, p.apply)
                overrides[key] = items
        return overrides, plant


def sample_seed(master_seed: int, sample: int) -> int:
    """The scenario seed of sample ``sample`` (a 32-bit integer)."""
    ss = np.random.SeedSequence(master_seed, spawn_key=(sample, SEED_KEY))
    return int(ss.generate_state(1, dtype=np.uint32)[0])


def run_id(values: dict[str, Any], seed: int) -> str:
    """16 hex digits of SHA-256 over the canonical JSON of the values and the seed."""
    text = json.dumps({"seed": seed, "values": values}, sort_keys=True, default=_jsonable)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(type(obj).__name__)


def _combine(base: Any, value: Any, mode: str) -> Any:
    if mode == "set":
        return value
    if isinstance(base, list):
        arr = np.asarray(base, dtype=float)
        out = arr * value if mode == "scale" else arr + value
        return [float(x) for x in out]
    return float(base * value if mode == "scale" else base + value)


_MISSING = object()


def _lookup(raw: dict[str, Any], key: str, default: Any = _MISSING) -> Any:
    node: Any = raw
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            if default is _MISSING:
                raise KeyError(key)
            return default
        node = node[part]
    return node


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
    head = dict(raw.get("study", {}))

    def pop(key, kind, default=_MISSING):
        if key not in head:
            if default is _MISSING:
                raise StudyError(f"{source}: study.{key}: is required")
            return default
        value = head.pop(key)
        if isinstance(value, bool) or not isinstance(value, kind):
            raise StudyError(f"{source}: study.{key}: must be {kind.__name__}, got {value!r}")
        return value

    name = pop("name", str, path.stem)
    description = pop("description", str, "")
    base_entry = pop("base", str)
    seed = pop("seed", int)
    samples = pop("samples", int, 1)
    if head:
        raise StudyError(f"{source}: [study] has unknown key(s): {', '.join(sorted(head))}")
    if seed < 0:
        raise StudyError(f"{source}: study.seed: must be >= 0, got {seed}")
    if samples < 1:
        raise StudyError(f"{source}: study.samples: must be >= 1, got {samples}")
    base = (path.parent / base_entry).resolve()
    if not base.is_file():
        raise StudyError(f"{source}: study.base: scenario '{base_entry}' not found ({base})")
    base_raw = read_toml(base, StudyError, f"{source}: study.base: '{base_entry}'")

    fixed = raw.get("fixed", {})
    if not isinstance(fixed, dict):
        raise StudyError(f"{source}: [fixed] must be a table of dotted keys")
    fixed = _flatten(fixed)
    for key in fixed:
        if key.startswith(PLANT_PREFIX):
            raise StudyError(f"{source}: fixed.{key}: plant factors go in a [[parameter]]")

    entries = raw.get("parameter", [])
    if not isinstance(entries, list) or not entries:
        raise StudyError(f"{source}: needs at least one [[parameter]]")
    parameters = []
    for k, entry in enumerate(entries):
        parameters.append(_parameter(entry, k, source, base_raw, fixed))
    seen = set()
    for p in parameters:
        if p.path in seen:
            raise StudyError(f"{source}: {p.entry}: the path is given twice")
        seen.add(p.path)

    report = raw.get("report", {})
    if not isinstance(report, dict):
        raise StudyError(f"{source}: [report] must be a table")
    _check_report(report, source, {p.path for p in parameters})

    study = Study(
        name,
        description,
        path,
        base,
        seed,
        samples,
        fixed,
        tuple(parameters),
        report,
        base_raw,
    )
    _check_against_base(study, source)
    return study


def _flatten(table: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in table.items():
        dotted = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(_flatten(value, dotted + "."))
        else:
            out[dotted] = value
    return out


def _number(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)


def _parameter(
    entry: Any, k: int, source: str, base_raw: dict[str, Any], fixed: dict[str, Any]
) -> Parameter:
    if not isinstance(entry, dict):
        raise StudyError(f"{source}: parameter[{k}]: must be a table")
    entry = dict(entry)
    path = entry.pop("path", None)
    if not isinstance(path, str):
        raise StudyError(f"{source}: parameter[{k}]: 'path' (a dotted key) is required")
    where = f"{source}: parameter[{k}] '{path}'"
    label = f"parameter[{k}] '{path}'"

    def fail(msg: str) -> StudyError:
        return StudyError(f"{where}: {msg}")

    if KEY_PATH.match(path) is None:
        raise fail("not a dotted key like 'environment.stiffness_N_m' or 'a.b[2]'")
    key, index = parse_key_path(path).key, parse_key_path(path).index
    apply = entry.pop("apply", "set")
    if apply not in APPLY_MODES:
        raise fail(f"apply must be one of {', '.join(APPLY_MODES)}, got {apply!r}")

    if path.startswith(PLANT_PREFIX):
        factor = path[len(PLANT_PREFIX) :]
        if factor not in PLANT_FACTORS or index is not None:
            raise fail(
                f"unknown plant factor; known: {', '.join(PLANT_PREFIX + f for f in PLANT_FACTORS)}"
            )
    else:
        base_value = fixed.get(key, _lookup(base_raw, key, None))
        if index is not None:
            if not isinstance(base_value, list):
                raise fail(f"'{key}' is not a list in the base scenario, it cannot be indexed")
            if int(index) >= len(base_value):
                raise fail(f"index {index} out of range: '{key}' has {len(base_value)} entries")
        elif apply != "set" and base_value is None:
            raise fail(f"apply = '{apply}' needs a value of '{key}' in the base scenario")

    kinds = [name for name in ("values", "linspace", "logspace", "distribution") if name in entry]
    if len(kinds) != 1:
        raise fail("give exactly one of values, linspace, logspace, distribution")
    kind = kinds[0]
    grid = None
    distribution = None
    args: dict[str, float] = {}
    if kind == "values":
        values = entry.pop("values")
        if not isinstance(values, list) or not values:
            raise fail("values: the list is empty")
        for v in values:
            ok = _number(v) or (isinstance(v, list) and v and all(_number(x) for x in v))
            if not ok:
                raise fail(f"values: {v!r} is not a finite number or list of numbers")
        grid = tuple(values)
    elif kind in ("linspace", "logspace"):
        spec = entry.pop(kind)
        if (
            not isinstance(spec, list)
            or len(spec) != 3
            or not all(_number(x) for x in spec[:2])
            or isinstance(spec[2], bool)
            or not isinstance(spec[2], int)
        ):
            raise fail(f"{kind}: must be [start, stop, count], got {spec!r}")
        start, stop, count = spec
        if count < 1:
            raise fail(f"{kind}: empty range (count = {count})")
        if count > 1 and start == stop:
            raise fail(f"{kind}: empty range (start = stop = {start})")
        if kind == "logspace":
            if start <= 0 or stop <= 0:
                raise fail(f"logspace: start and stop must be > 0, got {start}, {stop}")
            points = np.geomspace(start, stop, count)
        else:
            points = np.linspace(start, stop, count)
        grid = tuple(float(x) for x in points)
    else:
        distribution = entry.pop("distribution")
        if distribution not in DISTRIBUTIONS:
            raise fail(f"unknown distribution {distribution!r}; known: {', '.join(DISTRIBUTIONS)}")
        needed = ("mean", "std") if distribution == "normal" else ("low", "high")
        optional = ("low", "high") if distribution == "normal" else ()
        for name in (*needed, *optional):
            if name in entry:
                value = entry.pop(name)
                if not _number(value):
                    raise fail(f"{name}: must be a finite number, got {value!r}")
                args[name] = float(value)
            elif name in needed:
                raise fail(f"distribution '{distribution}' needs '{name}'")
        if distribution == "normal":
            if args["std"] <= 0:
                raise fail(f"std must be > 0, got {args['std']}")
            if args.get("low", -math.inf) >= args.get("high", math.inf):
                raise fail(f"empty range: low = {args['low']} >= high = {args['high']}")
        else:
            if args["low"] >= args["high"]:
                raise fail(f"empty range: low = {args['low']} >= high = {args['high']}")
            if distribution == "log-uniform" and args["low"] <= 0:
                raise fail(f"log-uniform needs low > 0, got {args['low']}")
    if entry:
        raise fail(f"unknown key(s): {', '.join(sorted(entry))}")
    return Parameter(path, label, apply, grid, distribution, args)


def _check_report(report: dict[str, Any], source: str, paths: set[str]) -> None:
    known = {"heatmaps", "metrics"}
    unknown = set(report) - known
    if unknown:
        raise StudyError(f"{source}: [report] has unknown key(s): {', '.join(sorted(unknown))}")
    for k, pair in enumerate(report.get("heatmaps", [])):
        if not (isinstance(pair, list) and len(pair) == 2 and set(pair) <= paths):
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
        if all(_number(v) for v in values):
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
    from uvms_pin.scenario.scenario import load_scenario

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
