"""Back end `ftplan`: each `ftplan` block becomes a module of the generated package holding its
configuration as data (`specc.runtime.ftplan.config`): the planners in their order, the recovery
policy, the watchdog, the plan analyzer's constraints and the rules updating FTplan's own state
from the reports it intercepts (seed 004 §3.3 called moving these out of FTplan's C++ code into
configuration "necessary work")."""

from __future__ import annotations

from dataclasses import dataclass

from specc.analysis.ftplan import ftplan_config
from specc.backends.env import render
from specc.backends.manifest import Output, header
from specc.backends.records import literal
from specc.backends.rules import python_name
from specc.model import nodes as m
from specc.runtime.ftplan import config as fc

BACKEND = "ftplan"


@dataclass
class FtPlanView:
    block: m.FtPlan
    config: fc.FtPlanConfig

    @property
    def header(self) -> str:
        return header(self.block.span.file)

    @property
    def summary(self) -> str:
        planners = ", ".join(f"{p.name} ({p.domain})" for p in self.config.planners)
        missions = ", ".join(m.name for m in self.config.missions) or "none"
        return (f"planners {planners}; {self.config.policy} planning; watchdog {self.config.watchdog:g} s; "
                f"{len(self.config.analyzer)} analyzer rules, {len(self.config.state_rules)} state rules; "
                f"missions {missions}")

    def source(self, value: object) -> str:
        return literal(value, (fc.Var, fc.Interval), 0)


def generate(program: m.Program, output: Output, robot: str = "") -> None:
    blocks = sorted((i for i in program.items if isinstance(i, m.FtPlan)), key=lambda b: b.name)
    for block in blocks:
        view = FtPlanView(block, ftplan_config(block, program))
        output.add(BACKEND, f"ftplan/{python_name(block.name)}.py", render("ftplan/block.py.j2", view=view))
    if blocks:
        output.add(BACKEND, "ftplan/__init__.py", render(
            "ftplan/__init__.py.j2", names=[python_name(b.name) for b in blocks],
            header=header("the ftplan blocks")))
