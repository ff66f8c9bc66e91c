from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
EXAMPLE_ROBOTS = ("hilare", "generic", "atrv")


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT
