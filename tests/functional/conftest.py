from __future__ import annotations

import importlib
import sys
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from specc.backends import generate_all, package
from specc.pipeline import load
from specc.runtime import functional as rt

HERE = Path(__file__).parent


def compile_robot(spec: Path | list[Path], target: Path, name: str | None = None) -> str:
    specs = spec if isinstance(spec, list) else [spec]
    loaded = load(specs)
    assert loaded.program is not None and not loaded.errors, [d.headline() for d in loaded.diagnostics]
    name = name or package.robot_name(loaded.program, specs[0].stem)
    generate_all(loaded.program, name).write(target / name)
    return name


def compiled_module(spec: Path | list[Path], target: Path, part: str) -> ModuleType:
    """One module of the package the specs compile to in `target` (`part`: `rules.guard`,
    `executive.x_resource_controller`), imported with `target` on the path only meanwhile."""
    name = compile_robot(spec, target)
    sys.path.insert(0, str(target))
    try:
        return importlib.import_module(f"{name}.{part}")
    finally:
        sys.path.remove(str(target))


@pytest.fixture(scope="session")
def scripted_package(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    target = tmp_path_factory.mktemp("generated")
    name = compile_robot(HERE / "scripted.spec", target)
    sys.path[:0] = [str(target), str(HERE)]
    return importlib.import_module(f"{name}.modules")


@dataclass
class Robot:
    registry: rt.Registry
    alpha: rt.Module
    beta: rt.Module
    package: ModuleType

    @property
    def kernel(self) -> Any:
        return self.registry.kernel

    def client(self, name: str = "alpha") -> rt.ModuleClient:
        return rt.ModuleClient(self.registry.modules[name])

    def script(self, text: str) -> Any:
        return self.package.alpha.AInput(script=text)


@pytest.fixture
def robot(scripted_package: ModuleType) -> Robot:
    registry = rt.Registry()
    made = scripted_package.create_all(registry)
    return Robot(registry, made["alpha"], made["beta"], scripted_package)


@pytest.fixture(scope="session")
def shop_package(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    """The scripted robot with the executive of executive.spec, as package `shop`."""
    target = tmp_path_factory.mktemp("generated")
    compile_robot([HERE / "scripted.spec", HERE / "executive.spec"], target, "shop")
    sys.path[:0] = [str(target), str(HERE)]
    return importlib.import_module("shop")
