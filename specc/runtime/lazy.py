"""A package that loads its modules on first use (PEP 562): `from specc.runtime.sim import World`
imports `specc.runtime.sim.world` then, and a program that needs one module of the package (a
generated configuration reading `specc.runtime.ftplan.config`, `specc check` reading world files)
does not import the rest (the search, numpy, pymunk)."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any


def lazy_exports(package: str, offers: Mapping[str, str]) -> Callable[[str], Any]:
    """The package's module `__getattr__`: each name of `offers` (name -> the module defining it)
    imported on first use, then kept in the package's namespace."""
    def __getattr__(name: str) -> Any:
        module = offers.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        setattr(importlib.import_module(package), name, value)
        return value

    return __getattr__
