"""What the front end works out from a file's text, kept on disk between commands.

A command is a new process: without this, every `specc check` or `specc plan` would parse each
spec file and read each codel module again (half of a cold `specc check`). An entry is keyed by
everything its value is computed from: the file's path and text, and the digest of the code that
computes it (`source_digest`), so an edit of either computes it again. Entries are written
atomically, since commands may run side by side, and a folder that cannot be written is no error:
the value is computed every time. SPECC_PARSE_CACHE=0 turns every cache off."""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import pickle
import tempfile
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from specc.files import write_bytes_atomically

ENTRY_SUFFIX = ".pickle"
ENTRIES_KEPT = 2000  # per kind; past it, the older half goes
MISSING = object()  # what `read` gives when nothing usable is kept


def root() -> Path | None:
    """specc's cache folder: $XDG_CACHE_HOME/specc (default ~/.cache/specc); when that cannot be
    made, a folder of this user's own in the temporary folder; None when neither can (no cache).
    An entry is a pickle, which runs code as it loads: a folder others may write in is refused."""
    configured = os.environ.get("XDG_CACHE_HOME", "")
    try:
        # A relative XDG_CACHE_HOME is to be ignored (the XDG base directory specification).
        folder = (Path(configured) if os.path.isabs(configured) else Path.home() / ".cache") / "specc"
        folder.mkdir(parents=True, exist_ok=True)
        return folder
    except (OSError, RuntimeError):  # RuntimeError: a user without a home folder
        pass
    private = Path(tempfile.gettempdir()) / f"specc-{os.getuid()}" if hasattr(os, "getuid") else None
    if private is None:
        return None
    try:
        private.mkdir(mode=0o700, exist_ok=True)
        status = private.stat()
    except OSError:
        return None
    return private if status.st_uid == os.getuid() and not status.st_mode & 0o022 else None


@functools.cache
def folder(kind: str) -> Path | None:
    """Where entries of `kind` are kept, or None: SPECC_PARSE_CACHE=0, or no folder can be made."""
    base = root()
    if os.environ.get("SPECC_PARSE_CACHE", "1") == "0" or base is None:
        return None
    place = base / kind
    try:
        place.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return place


def source_digest(files: Iterable[Path]) -> str:
    """The digest of the code a value is computed by (names and contents, in the order given)."""
    digest = hashlib.sha256()
    for path in files:
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def key(code: str, path: str, text: bytes) -> str:
    """The entry name for the value `code` computes from the file `path` holding `text`."""
    digest = hashlib.sha256(code.encode())
    digest.update(path.encode("utf-8", "surrogatepass"))
    digest.update(b"\0")
    digest.update(text)
    return digest.hexdigest()


def read(kind: str, name: str, expected: type | tuple[type, ...]) -> Any:
    """The entry `name` of `kind` when it holds an instance of `expected`; MISSING otherwise
    (absent, damaged, or written by another version of the code after all)."""
    place = folder(kind)
    if place is None:
        return MISSING
    try:
        with (place / (name + ENTRY_SUFFIX)).open("rb") as stream:
            value = pickle.load(stream)
    except Exception:  # absent or damaged (a damaged pickle raises almost anything): computed again
        return MISSING
    return value if isinstance(value, expected) else MISSING


def keep(kind: str, name: str, value: object) -> None:
    """Write the entry atomically (another process may write the same one)."""
    place = folder(kind)
    if place is None:
        return
    try:
        write_bytes_atomically(place / (name + ENTRY_SUFFIX), pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL))
    except (OSError, pickle.PicklingError, RecursionError):
        return
    _prune(place)


@functools.cache
def _prune(place: Path) -> None:
    """Past ENTRIES_KEPT entries the older half goes; looked at once per process and folder (the
    listing is not redone at every entry written)."""
    with contextlib.suppress(OSError):
        kept = list(place.glob("*" + ENTRY_SUFFIX))
        if len(kept) > ENTRIES_KEPT:
            kept.sort(key=lambda f: f.stat().st_mtime)
            for old in kept[:len(kept) // 2]:
                old.unlink(missing_ok=True)
