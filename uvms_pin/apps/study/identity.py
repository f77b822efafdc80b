"""A study directory holds one study: the inputs its rows came from, and the check on resume.

``study_inputs.json`` records what the rows were computed from: the study file's settings
(its parsed TOML, so that a comment or whitespace edit is not a different study), and
SHA-256 digests of the base scenario and of its model file (their bytes: any edit can
change a result), and the cap ``UVMS_PIN_MAX_DURATION_S`` put on its runs (None: full
length; `uvms_pin.sim.shortened`). A sweep into a directory whose record differs is refused: resuming would
put rows of two different studies into one table. Directories written before the record
existed are checked against their ``study.toml`` copy and the rows' ``base_sha256``.
"""

from __future__ import annotations

import hashlib
import json
import tomllib
from pathlib import Path
from typing import Any

from uvms_pin.apps.study.spec import Study
from uvms_pin.errors import StudyError
from uvms_pin.results.atomic import write_text_atomic
from uvms_pin.sim.shortened import MAX_DURATION_ENV, max_duration_s

INPUTS_FILE = "study_inputs.json"
STUDY_COPY = "study.toml"
WHAT_TO_DO = (
    "a study directory holds one study: rerun with a new --out, or with --overwrite to "
    "discard the results there"
)


def file_sha256(path: Path) -> str:
    """16 hex digits of the SHA-256 of a file's bytes (the per-row ``base_sha256``)."""
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16]


def model_path(study: Study) -> Path | None:
    """The base scenario's model file, as `load_scenario` resolves it (None if unnamed)."""
    entry = study.fixed.get("scenario.model", study.base_raw.get("scenario", {}).get("model"))
    if not isinstance(entry, str):
        return None
    return (study.base.parent / entry).resolve()


def study_inputs(study: Study) -> dict[str, Any]:
    """The record of what ``study``'s rows are computed from."""
    model = model_path(study)
    return {
        "study_file": str(study.path),
        "study_settings": _study_settings(study.path),
        "base": str(study.base),
        "base_sha256": file_sha256(study.base),
        "model": None if model is None else str(model),
        "model_sha256": file_sha256(model) if model is not None and model.is_file() else None,
        "max_duration_s": max_duration_s(),
    }


def _study_settings(path: Path) -> dict[str, Any]:
    return tomllib.loads(path.read_text(encoding="utf-8"))


def check_same_study(out: Path, study: Study, recorded_base_sha256: set[str]) -> None:
    """Raise StudyError if ``out`` holds results of a different study or inputs.

    ``recorded_base_sha256``: the ``base_sha256`` values of the rows already in ``out``.
    """
    now = study_inputs(study)
    inputs_file = out / INPUTS_FILE
    if inputs_file.is_file():
        then = json.loads(inputs_file.read_text(encoding="utf-8"))
    elif (out / STUDY_COPY).is_file():  # written before the record existed
        then = {"study_settings": _study_settings(out / STUDY_COPY)}
    else:
        then = {}
    if "study_settings" in then and _canonical(then["study_settings"]) != _canonical(
        now["study_settings"]
    ):
        raise StudyError(
            f"{out} holds the results of another study (its {STUDY_COPY} differs from "
            f"{study.path}); {WHAT_TO_DO}"
        )
    base_then = {then["base_sha256"]} if "base_sha256" in then else set()
    stale = (base_then | recorded_base_sha256) - {now["base_sha256"]}
    if stale:
        raise StudyError(
            f"{out}: the base scenario {study.base} changed since its results were recorded "
            f"(sha256 {', '.join(sorted(stale))} then, {now['base_sha256']} now); restore it, "
            f"or {WHAT_TO_DO}"
        )
    if then and then.get("max_duration_s") != now["max_duration_s"]:  # older records: None
        raise StudyError(
            f"{out}: its runs were made with {MAX_DURATION_ENV}={then.get('max_duration_s')} "
            f"(None: full length), and it is {now['max_duration_s']} now: a table must not mix "
            f"shortened and full runs; set it back, or {WHAT_TO_DO}"
        )
    if then.get("model_sha256") not in (None, now["model_sha256"]):
        raise StudyError(
            f"{out}: the model {now['model']} changed since its results were recorded "
            f"(sha256 {then['model_sha256']} then, {now['model_sha256']} now); restore it, "
            f"or {WHAT_TO_DO}"
        )


def _canonical(settings: dict[str, Any]) -> str:
    return json.dumps(settings, sort_keys=True, default=str)


def record_study_inputs(out: Path, study: Study) -> None:
    """Write ``study_inputs.json`` and the ``study.toml`` copy into ``out``."""
    write_text_atomic(
        out / INPUTS_FILE, json.dumps(study_inputs(study), indent=2, default=str) + "\n"
    )
    if study.path.resolve() != (out / STUDY_COPY).resolve():
        write_text_atomic(out / STUDY_COPY, study.path.read_text(encoding="utf-8"))
