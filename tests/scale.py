"""Robots of a chosen size with random conflicts (seeded), written as specs a user would write:
the executive-scale measurements of issue #24 (`make bench`) and the test that a controller grows
with the conflicts, not with their product (tests/test_controller_scale.py).

An executive of N services: modules of SERVICES_PER_MODULE exec requests each, one service per
request; in a module, each pair of requests is incompatible with probability `physical` (the
module interrupts one by itself); each service declares CONFLICTS_PER_SERVICE conflicts with
services drawn at random anywhere, interrupt or (one time in four) wait. A rule base of I inputs
x R rules: threshold rules on pairs of numeric inputs deciding a symbolic output.
"""

from __future__ import annotations

import random
from pathlib import Path

SERVICES_PER_MODULE = 5
CONFLICTS_PER_SERVICE = 2


def executive_spec(services: int, seed: int, physical: float = 0.3) -> tuple[str, dict[str, str]]:
    """The spec text of a robot whose executive has `services` services, and its codel files
    (path relative to the spec's folder -> Python source)."""
    rng = random.Random(seed)
    modules = [list(range(start, min(start + SERVICES_PER_MODULE, services)))
               for start in range(0, services, SERVICES_PER_MODULE)]
    lines: list[str] = []
    codels = {"scale_codels/__init__.py": ""}
    for number, members in enumerate(modules):
        lines += [f"module m{number} {{", f'  codels: "scale_codels.m{number}";']
        for i in members:
            clash = [f"R{j}" for j in members if j != i and rng.random() < physical]
            lines += [f"  request R{i} {{", "    type: exec;", "    task: Work;", "    codel exec: work;"]
            if clash:
                lines.append(f"    incompatible_with: {', '.join(clash)};")
            lines.append("  }")
        lines += ["  exec_task Work {", "    period: 100 ms;", "  }", "}", ""]
        codels[f"scale_codels/m{number}.py"] = "def work(sdi, request):\n    return \"end\"\n"
    lines.append(f"executive scale{services} {{")
    for number, members in enumerate(modules):
        for i in members:
            others = rng.sample([j for j in range(services) if j != i], min(CONFLICTS_PER_SERVICE, services - 1))
            conflicts = [f"      S{j}: {'wait' if rng.random() < 0.25 else 'interrupt'};" for j in sorted(others)]
            lines += [f"  service S{i} {{", f"    request: m{number}.R{i};", "    conflicts {", *conflicts,
                      "    }", "  }"]
    lines.append("}")
    return "\n".join(lines) + "\n", codels


def threshold_base(inputs: int, rules: int) -> str:
    """Numeric inputs tested against many thresholds, pairwise: the decision graph multiplies."""
    lines = [f"rules big {{\n  inputs {', '.join(f'x{i}: [0, 100]' for i in range(inputs))};",
             '  outputs level: {"LOW", "HIGH"};']
    for r in range(rules):
        a, b = r % inputs, (r * 3 + 1) % inputs
        lines.append(f'  r{r}: x{a} > {(r * 37) % 97 + 1}, x{b} < {(r * 53) % 89 + 5} ==> restrict level == '
                     f'"{"LOW" if r % 2 else "HIGH"}";')
    return "\n".join(lines) + "\n}\n"


def write_robot(folder: Path, services: int, seed: int) -> Path:
    text, codels = executive_spec(services, seed)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "robot.spec").write_text(text)
    for name, source in codels.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(source)
    return folder
