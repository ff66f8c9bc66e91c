"""Back end `systems`: each `system` block becomes `systems/<name>.py`, one `SystemSpec` (its
blocks, its body, its worlds and its missions) that `specc.run` drives the robot from."""

from __future__ import annotations

import posixpath
from dataclasses import dataclass

from specc.analysis.ftplan import term, terms
from specc.backends.env import Code, render
from specc.backends.manifest import Output, header
from specc.backends.records import literal
from specc.backends.rules import python_name
from specc.model import nodes as m
from specc.runtime.ftplan.config import Term, Var
from specc.runtime.system import BindingSpec, MissionSpec, ReportSpec, StateCondition, StateValue
from specc.syntax.printer import goal as goal_text
from specc.syntax.printer import prop_value

BACKEND = "systems"


def robot_folder(program: m.Program) -> str:
    """The folder of the robot's specs as the spans name it: the deepest one holding them all.
    Paths the package records are relative to it, and `specc.run` resolves them against the
    same folder of the specs it runs (`specc.syntax.parser.spec_root`)."""
    # `or "."`: the common path of "." and "sub" is "".
    return (posixpath.commonpath([posixpath.dirname(f.path) or "." for f in program.files]) or ".") if program.files \
        else "."


@dataclass(frozen=True)
class SystemView:
    system: m.System
    root: str  # robot_folder(program)

    @property
    def header(self) -> str:
        return header(self.system.span.file)

    @property
    def name(self) -> str:
        return self.system.name

    @property
    def name_literal(self) -> Code:
        return Code(repr(self.system.name))

    def names(self, refs: tuple[m.Ref, ...]) -> Code:
        return literal(tuple(r.text for r in refs))

    def optional(self, ref: m.Ref | None) -> Code:
        return Code(repr(ref.text if ref is not None else None))

    @property
    def extension(self) -> Code:
        return Code(repr(self.system.extension.value if self.system.extension is not None else None))

    @property
    def devices(self) -> Code:
        grants = self.system.devices
        if grants is None:
            return Code("None")
        return Code(repr({g.module: tuple(d.text for d in g.devices) for g in grants.entries}))

    @property
    def body(self) -> Code:
        entries = self.system.body.entries if self.system.body is not None else ()
        values = {s.name: s.value.value for s in entries if isinstance(s.value, m.Number)}
        return Code(f"RobotConfig.from_spec({self.name!r}, {values!r})")

    @property
    def worlds_declared(self) -> tuple[m.Setting, ...]:
        return self.system.worlds.entries if self.system.worlds is not None else ()

    @property
    def worlds(self) -> list[tuple[Code, Code]]:
        """(name, path relative to the robot's folder), each as a Python literal."""
        here = posixpath.dirname(self.system.span.file) or "."
        shown = []
        for entry in self.worlds_declared:
            written = prop_value(entry.value) if not isinstance(entry.value, m.String) else entry.value.value
            path = posixpath.relpath(posixpath.normpath(posixpath.join(here, written)), self.root)
            shown.append((Code(repr(entry.name)), Code(repr(path))))
        return shown

    @property
    def missions(self) -> list[tuple[Code, Code]]:
        worlds = self.worlds_declared
        only_world = worlds[0].name if len(worlds) == 1 else ""
        shown = []
        for mission in self.system.missions:
            spec = MissionSpec(mission.name, mission.world.text if mission.world is not None else only_world,
                               tuple(goal_text(g) for g in mission.goals),
                               mission.horizon.seconds if mission.horizon is not None else None,
                               mission.plan.text if mission.plan is not None else None)
            shown.append((Code(repr(mission.name)), literal(spec, (), 8, len(repr(mission.name)) + 2)))
        return shown


    @property
    def bindings(self) -> list[tuple[Code, Code]]:
        """(task, BindingSpec), each as a Python literal."""
        entries = self.system.bindings.entries if self.system.bindings is not None else ()
        return [(Code(repr(b.task)), literal(BindingSpec(
            b.task, terms(b.args), b.kind, b.target.text, tuple(binding_argument(a) for a in b.target_args),
            ReportSpec(b.report.name, tuple(v.text for v in b.report.values)) if b.report is not None else None,
            StateCondition(b.where.attribute, terms(b.where.args), term(b.where.value)) if b.where is not None
            else None),
            (Var, StateValue, ReportSpec, StateCondition), 8, len(repr(b.task)) + 2)) for b in entries]


def binding_argument(e: m.IxExpr) -> Term | StateValue:
    """A ?variable or a constant, or `ATTR(...)`: FTplan's state after the action."""
    if isinstance(e, m.IxCall):
        return StateValue(e.function, terms(e.args))
    return term(e)


def generate(program: m.Program, output: Output, robot: str = "") -> None:
    systems = sorted((i for i in program.items if isinstance(i, m.System)), key=lambda s: s.name)
    root = robot_folder(program)
    for system in systems:
        output.add(BACKEND, f"systems/{python_name(system.name)}.py",
                   render("systems/system.py.j2", view=SystemView(system, root)))
    if systems:
        output.add(BACKEND, "systems/__init__.py", render(
            "systems/__init__.py.j2", names=[python_name(s.name) for s in systems],
            header=header("the system blocks")))
