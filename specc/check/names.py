"""Every top-level name once per kind. Kinds have separate namespaces: a system refers to each
block through a typed property (`executive: tug`), so robot and executive may share a name.

A block's name also names a file of the generated package (`executive/tug.py`, imported by
`from . import tug`): it must be a name Python can import there, and two blocks of one folder
(an executive `ex` and its resource controller's `ex_resource_controller`) must not share one."""

from __future__ import annotations

from specc.check.context import KIND_WORDS, Context
from specc.model import nodes as m
from specc.pysource import python_name, python_name_problem, shadowed_by_the_standard_library

# The generated package's folder each kind's blocks are written into (problems and fragments
# become records inside a domain's file, not files of their own).
FOLDERS: dict[type, str] = {m.Module: "modules", m.Executive: "executive", m.RuleBase: "rules",
                            m.Procedures: "supervisor", m.Domain: "planner", m.FtPlan: "ftplan",
                            m.System: "systems"}
# Names the generated folders' __init__ files bind themselves (templates/*/__init__.py.j2): a block
# of that name would not be imported (`from . import rt` finds the runtime already bound there).
INIT_NAMES = frozenset({"annotations", "rt", "Mapping", "Any", "create_all", "MODULES", "EXECUTIVES", "FTPLANS",
                        "DOMAINS", "PROBLEMS", "RULE_BASES", "LIBRARIES", "SYSTEMS"})
CONTROLLER_SUFFIX = "_resource_controller"  # specc.analysis.controller's name for an executive's controller


def check(ctx: Context) -> None:
    for kind, word in KIND_WORDS.items():
        ctx.duplicates(list(ctx.items(kind)), word)
    files: dict[tuple[str, str], tuple[str, m.Node]] = {}  # (folder, file stem) -> (what, block)
    for kind, folder in FOLDERS.items():
        item: m.Node
        seen: set[str] = set()
        for item in ctx.items(kind):
            name: str = item.name  # type: ignore[attr-defined]  # every block kind has one
            if name in seen:  # a block written twice is reported as such, not as a clash of files
                continue
            seen.add(name)
            problem = python_name_problem(name)
            if problem is None and python_name(name) in INIT_NAMES:
                problem = f"'{python_name(name)}' is a name the generated {folder}/__init__.py uses itself"
            if problem is not None:
                ctx.report("reserved-name", f"{KIND_WORDS[kind]} '{name}' names a file of the generated "
                           f"package, but {problem}; rename it", item.span)
                continue
            stems = [(python_name(name), f"{KIND_WORDS[kind]} '{name}'")]
            if kind is m.Executive:  # its controller's rule base is compiled beside it
                stems.append((python_name(name + CONTROLLER_SUFFIX), f"the resource controller of executive "
                                                                        f"'{name}'"))
            for stem, what in stems:
                other = files.setdefault((folder, stem), (what, item))
                if other[1] is not item:
                    ctx.report("duplicate-definition", f"{what} and {other[0]} would both be written to "
                               f"{folder}/{stem}.py; rename one", item.span, (other[1].span, "the other one"))
    systems = list(ctx.items(m.System))
    if len(systems) == 1 and shadowed_by_the_standard_library(python_name(systems[0].name)):
        ctx.report("reserved-name", f"system '{systems[0].name}' names the generated package, but Python's "
                   f"standard library has a module of that name, which `import {systems[0].name}` would find "
                   "instead; rename it", systems[0].span)


