"""One robot configuration on one mission, ready for `FtPlan`: the configuration specialised to
the mission (each planner in its problem's domain, with the mission's correspondences), FTplan's
own problem (the state vocabulary's), each planner's problem and the domains the planners' processes
need, all taken from a generated package (`<robot>.ftplan.<block>` and `<robot>.planner`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import ModuleType

from specc.runtime.ftplan.config import VARIANTS_HELP, FtPlanConfig, configuration_named
from specc.runtime.planner import model as pm


class UnknownName(KeyError):
    """A configuration, mission or problem the generated package does not have; says which it has."""

    def __str__(self) -> str:
        return str(self.args[0])


@dataclass(frozen=True)
class MissionSetup:
    config: FtPlanConfig  # the configuration on the mission
    problem: pm.Problem  # FTplan's own statement of the mission: its facts and goals
    problems: dict[str, pm.Problem]  # each planner's
    domains: dict[str, pm.PlanningDomain]  # by name: those of the mission's problems

    @property
    def planned_in(self) -> set[str]:
        """The domains the configuration's planners plan in (fewer than `domains` for Robot2)."""
        return {planner.domain for planner in self.config.planners}


def mission_setup(configurations: Mapping[str, FtPlanConfig], configuration: str, mission: str,
                  planning: ModuleType) -> MissionSetup:
    """`configuration` ("Robot1/2") of a generated ftplan module's CONFIGURATIONS on `mission`
    ("M1"), with the problems and domains of the generated `planner` package `planning`."""
    try:
        base = configuration_named(configurations, configuration)
    except KeyError:
        known = ", ".join(f"{key} ({config.planners[0].name} alone)" if len(config.planners) == 1 else key
                          for key, config in configurations.items())
        several = "; one configuration each time: repeat the option for more" if "," in configuration else ""
        # Only a difference of case is hinted at: Robot3 is not a misspelt Robot2, robot1 is Robot1.
        folded = {key.lower(): key for key in configurations}
        hint = f" (did you mean '{folded[configuration.lower()]}'?)" if configuration.lower() in folded else ""
        raise UnknownName(f"no robot configuration '{configuration}'{hint} (known: {known}, or a planner's name "
                          f"for it alone; {VARIANTS_HELP}){several}") from None
    except ValueError as error:
        raise UnknownName(str(error)) from None
    try:
        config = base.for_mission(mission)
        statement = base.mission(mission)
    except KeyError as error:
        raise UnknownName(str(error.args[0])) from None
    problems: dict[str, pm.Problem] = {}
    domains: dict[str, pm.PlanningDomain] = {}
    wanted = [(p.planner, p.problem) for p in statement.problems]
    if not statement.state_problem:
        raise UnknownName(f"mission '{mission}' of ftplan '{base.name}' names no problem in FTplan's own "
                          "vocabulary (a planner without a view)")
    for name in dict.fromkeys([statement.state_problem] + [problem for _, problem in wanted]):
        module = planning.PROBLEMS.get(name)
        if module is None:
            raise UnknownName(f"the generated planner package has no problem '{name}': compile the robot again")
        problems[name] = module.PROBLEMS[name]
        domains[module.DOMAIN.name] = module.DOMAIN
    return MissionSetup(config, problems[statement.state_problem],
                        {planner: problems[problem] for planner, problem in wanted}, domains)
