"""The one place that knows where specc's data files live (they ship inside the wheel)."""

from __future__ import annotations

from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent


def _data_dir(name: str) -> Path:
    # Installed wheel: shipped as package data (specc/_data/<name>); source tree: the top-level folder.
    installed = PACKAGE_DIR / "_data" / name
    if installed.is_dir():
        return installed
    return PACKAGE_DIR.parent / name


def grammar_path() -> Path:
    return _data_dir("grammars") / "specc.lark"


def templates_dir() -> Path:
    return _data_dir("templates")
