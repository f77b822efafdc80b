"""Your own controller in a scenario: ``[controller] type = "package.module:ClassName"``.

The other keys of the ``[controller]`` table are the controller's parameters. The contract
of the class:

- it subclasses `uvms_pin.control.base.Controller` (``compute(time_s, measurement) ->
  tau``, optional ``reset``, ``signals``);
- it is built for one loaded model as ``ClassName.from_params(uvms, params)`` when the
  class defines that classmethod (``params``: a dict of the table's other keys), else as
  ``ClassName(uvms, **params)``.

The module is imported from ``sys.path`` with the scenario file's directory in front, so a
``my_controller.py`` next to the scenario works without installing anything. A module is
imported once per process (Python's module cache): two scenario directories with modules
of the same name share the first one imported.
"""

from __future__ import annotations

import importlib
import keyword
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from uvms_pin.control.base import Controller
from uvms_pin.errors import ParameterError, user_traceback
from uvms_pin.model.uvms import UVMS
from uvms_pin.scenario.overrides import closest
from uvms_pin.sim.run import ControllerSpec

__all__ = ["custom_controller", "load_controller_class"]


def load_controller_class(type_path: str, search_dir: str | Path | None = None) -> type:
    """The class named by ``"package.module:ClassName"``.

    Raises:
        ParameterError: a malformed name, a module that is not found or fails to import, a
            missing attribute (with the closest name), or not a `Controller` subclass.
    """
    module_name, _, class_name = type_path.partition(":")
    if not (_dotted_identifier(module_name) and _dotted_identifier(class_name)):
        raise ParameterError(f"controller type '{type_path}': expected 'package.module:ClassName'")
    module = _import(module_name, type_path, search_dir)
    obj: Any = module
    for part in class_name.split("."):
        if not hasattr(obj, part):
            names = [n for n in dir(obj) if not n.startswith("_")]
            hint = closest(part, names)
            raise ParameterError(
                f"controller type '{type_path}': module '{module_name}' has no '{class_name}'"
                + (f"; did you mean '{hint}'?" if hint else "")
            )
        obj = getattr(obj, part)
    if not (isinstance(obj, type) and issubclass(obj, Controller)):
        raise ParameterError(
            f"controller type '{type_path}': must be a class derived from "
            "uvms_pin.control.base.Controller"
        )
    return obj


def custom_controller(
    type_path: str, params: Mapping[str, Any], search_dir: str | Path | None = None
) -> ControllerSpec:
    """The `ControllerSpec` of a ``module:Class`` controller (the class is imported now)."""
    cls = load_controller_class(type_path, search_dir)
    frozen = dict(params)

    def build(uvms: UVMS) -> Controller:
        try:
            if hasattr(cls, "from_params"):
                controller = cls.from_params(uvms, dict(frozen))
            else:
                controller = cls(uvms, **frozen)
        except Exception as exc:  # the user's constructor: its traceback goes with it
            raise _users_code_failed(
                f"controller '{type_path}' rejected its parameters "
                f"({', '.join(sorted(frozen)) or 'none'}): {type(exc).__name__}: {exc}",
                exc,
            ) from exc
        if not isinstance(controller, Controller):
            raise ParameterError(
                f"controller '{type_path}': from_params returned a {type(controller).__name__}, "
                "not a Controller"
            )
        return controller

    return ControllerSpec(type_path, frozen, build)


def _users_code_failed(message: str, exc: BaseException) -> ParameterError:
    """A ParameterError saying ``message``, with the frames of the user's code that raised
    ``exc`` (`uvms_pin.errors.user_traceback`) for the command line to show."""
    error = ParameterError(message)
    error.user_traceback = user_traceback(exc)
    return error


def _dotted_identifier(text: str) -> bool:
    parts = text.split(".")
    return bool(text) and all(p.isidentifier() and not keyword.iskeyword(p) for p in parts)


def _import(module_name: str, type_path: str, search_dir: str | Path | None):
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
                f"controller type '{type_path}': module '{module_name}' not found on "
                f"sys.path{where}"
            ) from exc
        raise ParameterError(
            f"controller type '{type_path}': importing '{module_name}' failed: {exc}"
        ) from exc
    except Exception as exc:  # the user's module raised while importing: name it
        raise _users_code_failed(
            f"controller type '{type_path}': importing '{module_name}' failed: "
            f"{type(exc).__name__}: {exc}",
            exc,
        ) from exc
    finally:
        if added is not None:
            sys.path.remove(added)
