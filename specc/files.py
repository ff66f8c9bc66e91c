"""Writing a file so that no reader ever sees half of it.

A spec `specc fmt` rewrites, a module `specc compile` generates, a cache entry: each is written
into a temporary file beside it, then renamed over it (an atomic step on one file system), so
that a crash, a full disk or a command running side by side (`specc run` importing the package
another `specc compile` is writing) finds the old file or the new one, never a truncated one."""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from pathlib import Path


def write_bytes_atomically(path: Path, data: bytes) -> None:
    """Write `data` as the whole of `path` (OSError as `Path.write_bytes` raises it; the file is
    then unchanged). The file keeps its permissions when it existed."""
    try:
        mode: int | None = path.stat().st_mode & 0o7777
    except OSError:
        mode = None
    if mode is not None and not os.access(path, os.W_OK):  # renaming over it would ignore that it is read-only
        raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(path))
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
        if mode is not None:
            os.chmod(temporary, mode)
        else:  # mkstemp's 0600, widened as a new file's would be under the user's umask
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(temporary, 0o666 & ~umask)
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        raise


def write_text_atomically(path: Path, text: str) -> None:
    write_bytes_atomically(path, text.encode("utf-8"))
