"""A package that loads its modules on first use (PEP 562): `from specc.runtime.sim import World`
imports `specc.runtime.sim.world` then, and a program that needs one module of the package (a
generated configuration reading `specc.runtime.ftplan.config`, `specc check` reading world files)
does not import the rest (the search, numpy, pymunk)."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable, Mapping
from typing import Any


def lazy_exports(package: str, offers: Mapping[str, Iterable[str]]) -> Callable[[str], Any]:
    """The package's module `__getattr__`: the names each of its modules offers (module name,
    relative to the package -> names), each imported on first use, then kept in the package's
    namespace."""
    defined_in = {name: f"{package}.{module}" for module, names in offers.items() for name in names}

    def __getattr__(name: str) -> Any:
        module = defined_in.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        setattr(importlib.import_module(package), name, value)
        return value

    return __getattr__
