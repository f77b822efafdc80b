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

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from uvms_pin.control.base import Controller
from uvms_pin.control.spec import ControllerSpec
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.results.named import resolve_reference, users_code_failed
from uvms_pin.scenario.controller_parts import ControllerContext
from uvms_pin.scenario.schema import Table

__all__ = ["custom_controller", "load_controller_class", "read_custom"]


def load_controller_class(type_path: str, search_dir: str | Path | None = None) -> type:
    """The class named by ``"package.module:ClassName"``.

    Raises:
        ParameterError: a malformed name, a module that is not found or fails to import, a
            missing attribute (with the closest name), or not a `Controller` subclass.
    """
    obj = resolve_reference(type_path, search_dir, what="controller type", form="ClassName")
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
        except ParameterError as exc:  # a refusal the class made on purpose: its message
            raise ParameterError(
                f"controller '{type_path}' rejected its parameters: {exc}"
            ) from exc
        except Exception as exc:  # the user's constructor failed: its traceback goes with it
            raise users_code_failed(
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


def read_custom(type_path: str, t: Table, context: ControllerContext) -> ControllerSpec:
    """[controller] type = "package.module:ClassName": the table's other keys are the
    class's parameters; the module is searched next to the scenario file first."""
    return custom_controller(type_path, t.rest(), context.scenario_dir)
