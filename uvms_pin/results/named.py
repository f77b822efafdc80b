"""Objects named by text, ``"package.module:name"``: your own controller class, your own
metric function. The module is imported from ``sys.path``, with a given directory (the
scenario file's) in front, so a ``my_metrics.py`` next to a scenario works uninstalled.

A module is imported once per process (Python's module cache): two directories with
modules of the same name share the first one imported.
"""

from __future__ import annotations

import difflib
import importlib
import keyword
import sys
from pathlib import Path
from typing import Any

from uvms_pin.errors import ParameterError, user_traceback

__all__ = ["resolve_reference", "users_code_failed"]


def resolve_reference(
    reference: str, search_dir: str | Path | None = None, *, what: str, form: str = "Name"
) -> Any:
    """The object ``"package.module:Name"`` names (``Name`` may be dotted: ``Class.method``).

    Args:
        reference: the text. search_dir: a directory put in front of ``sys.path`` while
            importing (None: ``sys.path`` as it is). what: how messages name the reference
            ("controller type", "metric"). form: what the part after the colon names, in
            the message about a malformed reference ("ClassName", "function").

    Raises:
        ParameterError: a malformed name, a module not found or failing to import, a
            missing attribute (with the closest name).
    """
    module_name, _, attribute = str(reference).partition(":")
    if not (_dotted_identifier(module_name) and _dotted_identifier(attribute)):
        raise ParameterError(f"{what} '{reference}': expected 'package.module:{form}'")
    obj: Any = _import(module_name, reference, search_dir, what)
    for part in attribute.split("."):
        if not hasattr(obj, part):
            names = [n for n in dir(obj) if not n.startswith("_")]
            hint = difflib.get_close_matches(part, sorted(names), n=1, cutoff=0.6)
            raise ParameterError(
                f"{what} '{reference}': module '{module_name}' has no '{attribute}'"
                + (f"; did you mean '{hint[0]}'?" if hint else "")
            )
        obj = getattr(obj, part)
    return obj


def users_code_failed(message: str, exc: BaseException) -> ParameterError:
    """A ParameterError saying ``message``, with the frames of the user's code that raised
    ``exc`` (`uvms_pin.errors.user_traceback`) for the command line to show."""
    error = ParameterError(message)
    error.user_traceback = user_traceback(exc)
    return error


def _dotted_identifier(text: str) -> bool:
    parts = text.split(".")
    return bool(text) and all(p.isidentifier() and not keyword.iskeyword(p) for p in parts)


def _import(module_name: str, reference: str, search_dir: str | Path | None, what: str):
    added = None
    if search_dir is not None:
        added = str(Path(search_dir).resolve())
        sys.path.insert(0, added)
    try:
        return importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name is not None and (module_name + ".").startswith(exc.name + "."):
            where = f" or in {added}" if added else ""
            raise ParameterError(
                f"{what} '{reference}': module '{module_name}' not found on sys.path{where}"
            ) from exc
        raise ParameterError(
            f"{what} '{reference}': importing '{module_name}' failed: {exc}"
        ) from exc
    except Exception as exc:  # the user's module raised while importing: name it
        raise users_code_failed(
            f"{what} '{reference}': importing '{module_name}' failed: {type(exc).__name__}: {exc}",
            exc,
        ) from exc
    finally:
        if added is not None:
            sys.path.remove(added)
