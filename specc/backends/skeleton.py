"""`specc skeleton`: stubs for the Python functions a spec names but its modules lack: module
codels, executive input/output functions, PRS actions and evaluable predicates.

User code is never rewritten: a missing codel module is created, an existing one only gets
the missing functions appended at its end.
"""

from __future__ import annotations

import keyword
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
    returns: str  # a Python expression: what the stub returns

    @property
    def text(self) -> str:
        return (f"\n\ndef {self.function}({self.signature}):\n    \"\"\"{self.doc}\"\"\"\n"
                f"    return {self.returns}\n")


@dataclass(frozen=True)
class Change:
    path: Path
    created: bool
    functions: tuple[str, ...]


@dataclass(frozen=True)
class Needs:
    """The functions one Python module must define for one block of the specs."""

    owner: str  # "module loco", "executive yard", "procedures tasks": its file's docstring
    dotted: str  # the Python module, as the spec names it
    stubs: tuple[Stub, ...]


def needs(item: m.Node) -> list[Needs]:
    """What each block names in Python: module codels, executive input/output functions, PRS
    actions and evaluable predicates."""
    if isinstance(item, m.Module) and item.codel_module is not None:
        return [Needs(f"module {item.name}", item.codel_module.value, tuple(needed(item)))]
    if isinstance(item, m.Executive) and item.codel_module is not None:
        return [Needs(f"executive {item.name}", item.codel_module.value, tuple(executive_functions(item)))]
    if isinstance(item, m.Procedures):
        by_module: dict[str, list[Stub]] = {}
        for dotted, stub in procedure_functions(item):
            by_module.setdefault(dotted, []).append(stub)
        return [Needs(f"procedures {item.name}", dotted, tuple(stubs)) for dotted, stubs in by_module.items()]
    return []


def executive_functions(executive: m.Executive) -> Iterator[Stub]:
    for service in executive.services:
        request = service.request.text if service.request is not None else "its request"
        if service.input is not None and len(service.input.parts) == 1:
            yield Stub(service.input.text, "ctx",
                       f"Input of service {service.name}: a dict of {request}'s inputs (or the value of its only "
                       f"one), completing the service's args.", "{}")
        if service.output is not None and len(service.output.parts) == 1:
            yield Stub(service.output.text, "ctx, output",
                       f"Output of service {service.name}: the result the task level hears from {request}'s "
                       f"output.", '"OK"')


def procedure_functions(procedures: m.Procedures) -> Iterator[tuple[str, Stub]]:
    """(Python module, stub) for each action and evaluable predicate bound to a function, called
    as function(ctx, *args)."""
    for action in procedures.actions:
        if isinstance(action.binding, m.String):
            dotted, _, function = action.binding.value.rpartition(".")
            value = "its value" if action.result is not None else "nothing"
            yield dotted, Stub(function, ", ".join(["ctx", *(python_parameter(p.name) for p in action.params)]),
                               f"Action {action.name} of procedures {procedures.name}: returns {value}.",
                               "0" if action.result is not None else "None")
    for predicate in procedures.predicates:
        if predicate.binding is not None:
            dotted, _, function = predicate.binding.value.rpartition(".")
            yield dotted, Stub(function, ", ".join(["ctx", *(python_parameter(p.name) for p in predicate.params)]),
                               f"Evaluable predicate {predicate.name} of procedures {procedures.name}: true or "
                               "false now.", "False")


def python_parameter(name: str) -> str:
    """A PRS parameter as a Python parameter name (PRS names may hold '-' or be keywords)."""
    text = "".join(c if c.isalnum() or c == "_" else "_" for c in name.lower()) or "arg"
    return f"{text}_" if keyword.iskeyword(text) or text[0].isdigit() else text


def needed(module: m.Module) -> Iterator[Stub]:
    """One stub per codel function the module names (a function used twice gets one stub)."""
    for request in module.requests:
        fail = ", ".join(f.text for f in request.fail) or "none declared"
        if request.validate is not None:
            yield Stub(request.validate.text, "sdi, request",
                       f"Validate request {request.name} of {module.name}: return \"end\" to accept, or a fail "
                       f"message ({fail}).", '"end"')
        for codel in request.codels:
            yield Stub(codel.function, "sdi, request",
                       f"Codel '{codel.state}' of request {request.name} ({module.name}): return the next state "
                       f"(a codel state, \"end\", \"ether\" when done, \"zombie\") or a fail message ({fail}).",
                       f'"{next_state(codel)}"')
    for task in module.exec_tasks:
        for codel in task.codels:
            yield Stub(codel.function, "sdi",
                       f"The {codel.state} codel of exec task {task.name} ({module.name}): runs "
                       f"{'once at start' if codel.state == 'init' else 'every period'} on the internal data.",
                       '"exec"')


def next_state(codel: m.Codel) -> str:
    """What the stub returns: the usual next state, within what the spec declares it may return."""
    usual = FIRST_NEXT_STATE.get(codel.state, "ether")
    if not codel.yields or usual in codel.yields:
        return usual
    return "ether" if "ether" in codel.yields else codel.yields[0]


def write_stubs(wanted: Needs, spec_dir: Path, robot_dir: Path | None = None) -> Change | None:
    """Add the missing stubs to the module `wanted` names, found as `specc check` finds it (from
    the spec's folder up); a module found nowhere is created in `robot_dir` (the robot's folder,
    where `specc run` imports codels from), else beside the spec."""
    if not wanted.stubs or not all(part.isidentifier() for part in wanted.dotted.split(".")):
        return None  # no Python module can take that name: `specc check` says so
    dotted = wanted.dotted
    path = find_module(dotted, spec_dir)
    created = path is None
    if path is None:
        base = robot_dir or spec_dir
        path = base.joinpath(*dotted.split(".")).with_suffix(".py")
        path.parent.mkdir(parents=True, exist_ok=True)
        for folder in path.parent.relative_to(base).parents:
            init = base / folder / "__init__.py" if str(folder) != "." else None
            if init is not None and not init.exists():
                init.write_text("")
        package_init = path.parent / "__init__.py"
        if path.parent != base and not package_init.exists():
            package_init.write_text("")
        path.write_text(f'"""Functions of {wanted.owner} (stubs written by `specc skeleton`)."""\n')
    existing = top_level_functions(path)
    if isinstance(existing, OSError):
        raise existing
    if isinstance(existing, SyntaxError):
        raise SyntaxError(f"{path}:{existing.lineno}: cannot add functions to a file with a syntax error: "
                          f"{existing.msg}")
    stubs: dict[str, Stub] = {}
    for stub in wanted.stubs:
        if stub.function not in existing and stub.function not in stubs:
            stubs[stub.function] = stub
    if not stubs:
        return Change(path, created, ())
    with path.open("a", encoding="utf-8") as handle:
        for stub in stubs.values():
            handle.write(stub.text)
    return Change(path, created, tuple(stubs))
