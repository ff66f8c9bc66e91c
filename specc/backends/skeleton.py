"""`specc skeleton`: stubs for the codels a spec names but its Python codel modules lack.

User code is never rewritten: a missing codel module is created, an existing one only gets
the missing functions appended at its end.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from specc.model import nodes as m
from specc.pysource import find_module, top_level_functions

FIRST_NEXT_STATE = {"start": "exec", "exec": "ether", "end": "ether", "inter": "ether"}


@dataclass(frozen=True)
class Stub:
    function: str
    signature: str
    doc: str
    result: str

    @property
    def text(self) -> str:
        return (f"\n\ndef {self.function}({self.signature}):\n    \"\"\"{self.doc}\"\"\"\n"
                f"    return \"{self.result}\"\n")


@dataclass(frozen=True)
class Change:
    path: Path
    created: bool
    functions: tuple[str, ...]


def needed(module: m.Module) -> Iterator[Stub]:
    """One stub per codel function the module names (a function used twice gets one stub)."""
    for request in module.requests:
        fail = ", ".join(f.text for f in request.fail) or "none declared"
        if request.validate is not None:
            yield Stub(request.validate.text, "sdi, request",
                       f"Validate request {request.name} of {module.name}: return \"end\" to accept, or a fail "
                       f"message ({fail}).", "end")
        for codel in request.codels:
            yield Stub(codel.function, "sdi, request",
                       f"Codel '{codel.state}' of request {request.name} ({module.name}): return the next state "
                       f"(a codel state, \"end\", \"ether\" when done, \"zombie\") or a fail message ({fail}).",
                       next_state(codel))
    for task in module.exec_tasks:
        for codel in task.codels:
            yield Stub(codel.function, "sdi",
                       f"The {codel.state} codel of exec task {task.name} ({module.name}): runs "
                       f"{'once at start' if codel.state == 'init' else 'every period'} on the internal data.",
                       "exec")


def next_state(codel: m.Codel) -> str:
    """What the stub returns: the usual next state, within what the spec declares it may return."""
    usual = FIRST_NEXT_STATE.get(codel.state, "ether")
    if not codel.yields or usual in codel.yields:
        return usual
    return "ether" if "ether" in codel.yields else codel.yields[0]


def write_stubs(module: m.Module, spec_dir: Path) -> Change | None:
    if module.codel_module is None:
        return None
    dotted = module.codel_module.value
    path = find_module(dotted, spec_dir)
    created = path is None
    if path is None:
        path = spec_dir.joinpath(*dotted.split(".")).with_suffix(".py")
        path.parent.mkdir(parents=True, exist_ok=True)
        for folder in path.parent.relative_to(spec_dir).parents:
            init = spec_dir / folder / "__init__.py" if str(folder) != "." else None
            if init is not None and not init.exists():
                init.write_text("")
        package_init = path.parent / "__init__.py"
        if path.parent != spec_dir and not package_init.exists():
            package_init.write_text("")
        path.write_text(f'"""Codels of module {module.name} (stubs written by `specc skeleton`)."""\n')
        top_level_functions.cache_clear()
    existing = top_level_functions(path)
    if isinstance(existing, SyntaxError):
        raise SyntaxError(f"{path}:{existing.lineno}: cannot add codels to a file with a syntax error: "
                          f"{existing.msg}")
    stubs: dict[str, Stub] = {}
    for stub in needed(module):
        if stub.function not in existing and stub.function not in stubs:
            stubs[stub.function] = stub
    if not stubs:
        return Change(path, created, ())
    with path.open("a", encoding="utf-8") as handle:
        for stub in stubs.values():
            handle.write(stub.text)
    top_level_functions.cache_clear()
    return Change(path, created, tuple(stubs))
