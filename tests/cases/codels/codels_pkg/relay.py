"""Codels of the test module `relay`, all taken from other modules (re-exports): `specc check`
follows `from ... import` into the robot's own modules, relative or absolute, and checks the
function found there; a name from outside the robot (the standard library) is not checked, and
an import circle ends. Never run."""

from os.path import join as outside

from codels_pkg.hand import check_grip
from codels_pkg.relay import circle

from .hand import release, squeeze as grab

raise RuntimeError("codel modules must never be executed by `specc check`")
