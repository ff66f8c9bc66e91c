"""A system says how one robot runs: the blocks it is made of (each must exist and be of the
right kind), its simulated body, its worlds and its missions, and how its procedures reach the
executive's services. Names are resolved across layers here, so that what `check` accepts runs:
a mission's goal is one its supervisor can achieve, an action bound to a service gives that
service exactly the inputs it takes, with values of their types."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from specc.check.codels import check_call, python_functions
from specc.check.context import Context
from specc.check.executive import (
    NUMERIC_INPUTS,
    TEXT_INPUTS,
    WHOLE_INPUTS,
    module_enums,
    refused_values,
    resolve_poster,
    resolve_request,
)
from specc.check.ftplan import check_attribute, check_bound, check_task, check_terms, planned_tasks, planner_tables
from specc.check.planning import DomainTables
from specc.check.procedures import Domains
from specc.check.symbols import first_by_name
from specc.diagnostics import did_you_mean
from specc.model import nodes as m
from specc.model.visitor import walk
from specc.runtime.body import BODY_KEYS, DEVICES, RobotConfig, body_problem
from specc.runtime.sim.world import WorldError, load_world

# The PRS domains a request input of each type accepts (seed 000 §4.2: the task level passes
# numbers and symbols; records are the functional level's business).
NUMERIC_DOMAINS = frozenset({"int", "float", "number"})
TEXT_DOMAINS = frozenset({"string", "symbol"})
# The hooks a system's extension module may define, and how the runner calls them
# (docs/reference.md, "A robot's extension module").
EXTENSION_HOOKS = {"prepare": ("world", "setup"), "attach": ("run",), "measure": ("events",),
                   "judge": ("events", "measures", "outcome", "why")}
# Achieve, test, or a fact the supervisor's database holds from the start (what the robot knows
# of its world before it starts: where the objects are): what a mission can give the supervisor.
MISSION_GOAL_OPS = ("!", "?", "=>")


def check(ctx: Context) -> None:
    systems = list(ctx.items(m.System))
    for system in systems:
        check_blocks(ctx, system)
        check_body(ctx, system)
        check_devices(ctx, system)
        worlds = check_worlds(ctx, system)
        check_missions(ctx, system, worlds)
        executive = ctx.named(m.Executive).get(system.executive.text) if system.executive else None
        supervisor = ctx.named(m.Procedures).get(system.supervisor.text) if system.supervisor else None
        check_planning(ctx, system, supervisor, executive)
        if supervisor is not None and (executive is not None or system.executive is None):
            without = f"system '{system.name}' has no executive: give it 'executive: NAME;'"
            check_service_actions(ctx, supervisor, [executive] if executive is not None else [], without)
            check_executive_goals(ctx, supervisor, [executive] if executive is not None else [], without,
                                  system.missions)
            if executive is not None:
                check_reply_domain(ctx, supervisor, executive)
    # Procedures no system runs: their services are looked for in every executive.
    supervised = {s.supervisor.text for s in systems if s.supervisor is not None}
    for procedures in ctx.items(m.Procedures):
        if procedures.name not in supervised:
            executives = list(ctx.items(m.Executive))
            check_service_actions(ctx, procedures, executives, "no executive offers services: declare one")
            check_executive_goals(ctx, procedures, executives, "no system connects these procedures to an "
                                  "executive: add 'supervisor:' and 'executive:' to a system block")


def check_reply_domain(ctx: Context, procedures: m.Procedures, executive: m.Executive) -> None:
    """A finite result domain of the procedures' `REPLY(id, result)` holds every fail code the
    modules may answer for the services the procedures name, and the statuses a broken codel
    ends a request with (FINAL_ERROR; SERVER_ERROR for one that sends requests): a reply carrying
    another reaches them outside what `specc verify --goal` assumes (the run notes an incident
    when it happens)."""
    reply = next((p for p in procedures.predicates if p.name == "REPLY" and len(p.params) == 2), None)
    allowed = Domains(procedures).values(reply.params[1].domain) if reply is not None else None
    if reply is None or allowed is None:
        return
    named = {a.binding.service for a in procedures.actions if isinstance(a.binding, m.ServiceBinding)}
    named |= {v for n in walk(procedures) if isinstance(n, m.SymbolSet) for v in n.values}
    missing: dict[str, list[str]] = {}
    every: list[str] = []  # the services named that run a request
    for service in executive.services:
        request = ctx.symbols.service_request(service) if service.name in named else None
        if request is None:
            continue
        every.append(service.name)
        # Its fail codes, and the module's status when a codel breaks: one that raises (or a
        # validate codel refusing) ends the request FINAL_ERROR, a child's error SERVER_ERROR.
        runs_codels = request.kind != "control" or request.validate is not None
        breaks = (["FINAL_ERROR"] if runs_codels else []) + (["SERVER_ERROR"] if request.sends else [])
        for code in [c.text for c in request.fail] + breaks:
            if code not in allowed:
                missing.setdefault(code, []).append(service.name)
    if missing:
        said = ", ".join(f"{code} ({'every service they name' if services == every else ', '.join(services)})"
                         for code, services in sorted(missing.items()))
        ctx.warn("incomplete-reply-domain", f"REPLY's result domain lacks result(s) the services the procedures "
                 f"name may answer: {said}; a reply carrying one reaches the procedures outside the domain "
                 "`specc verify --goal` assumes (a run notes an incident): add them to it", reply.params[1].span)


def check_blocks(ctx: Context, system: m.System) -> None:
    for ref in system.modules:
        ctx.lookup(m.Module, ref, ref.span, "undefined-module")
    single: tuple[tuple[m.Ref | None, type, str], ...] = (
        (system.executive, m.Executive, "undefined-executive"),
        (system.supervisor, m.Procedures, "undefined-procedures"),
        (system.planning, m.FtPlan, "undefined-ftplan"))
    for reference, kind, code in single:
        if reference is not None:
            ctx.lookup(kind, reference, reference.span, code)
    if system.extension is not None:
        functions = python_functions(ctx, system.extension)  # reports a module that is not there
        for hook, call in EXTENSION_HOOKS.items():
            if functions is not None and hook in functions:
                check_call(ctx, hook, functions[hook], call, system.extension.value, system.extension.span)
    if not system.modules:
        ctx.report("missing-property", f"system '{system.name}' needs 'modules: ...;'", system.span)
        return
    executive = ctx.named(m.Executive).get(system.executive.text) if system.executive else None
    listed = {ref.text for ref in system.modules}
    for service in executive.services if executive is not None else ():
        module = service.request.parts[0] if service.request is not None else None
        if module is not None and module not in listed and module in ctx.named(m.Module):
            ctx.report("undefined-module", f"service '{service.name}' runs a request of module '{module}', which "
                       f"system '{system.name}' does not list: add it to 'modules:'", service.request.span)  # type: ignore[union-attr]


def check_devices(ctx: Context, system: m.System) -> None:
    """Each grant names one of the system's modules and devices of the simulated body."""
    if system.devices is None:
        return
    ctx.duplicates(system.devices.entries, "devices of module", key="module")
    declared = ctx.named(m.Module)
    listed = {ref.text for ref in system.modules}
    misspelt = listed - set(declared)  # reported where `modules:` names them
    body = {e.name: e.value for e in system.body.entries} if system.body is not None else {}
    present = {"sonars": "sonars", "laser": "laser_beams", "arm": "arm_joints"}  # devices a body may lack
    for grant in system.devices.entries:
        if grant.module not in listed:
            if grant.module in declared and misspelt:
                continue  # most likely the one misspelt in `modules:`: one error, there, is enough
            ctx.unknown("undefined-module", "module", grant.module, listed - misspelt, grant.span,
                        f" of system '{system.name}' (its modules get devices)")
        for device in grant.devices:
            if device.text not in DEVICES:
                ctx.unknown("undefined-device", "device", device.text, DEVICES, device.span,
                            f"; the simulated body has {', '.join(DEVICES)}")
            elif device.text in present:
                count = body.get(present[device.text])
                if not (isinstance(count, m.Number) and count.value > 0):
                    ctx.report("undefined-device", f"module '{grant.module}' is given the {device.text}, but the body "
                               f"has none: give it '{present[device.text]}: N;'", device.span)


def check_body(ctx: Context, system: m.System) -> None:
    body = system.body.entries if system.body is not None else ()
    ctx.duplicates(body, "body key")
    for entry in body:
        if entry.name not in BODY_KEYS:
            ctx.report("unknown-property", f"a body has no key '{entry.name}'{did_you_mean(entry.name, BODY_KEYS)}; "
                       f"known: {', '.join(BODY_KEYS)}", entry.span)
            continue
        value = entry.value
        unit = BODY_KEYS[entry.name].unit or "a count"
        if not isinstance(value, m.Number):
            ctx.report("bad-property-value", f"'{entry.name}' expects a number ({unit})", value.span)
            continue
        problem = body_problem(entry.name, float(value.value))
        if problem is not None:
            ctx.report("bad-property-value", problem, value.span)
    # A box footprint takes both sides: one alone would leave the simulator a box of width 0.
    box = {e.name: e for e in body if e.name in ("length", "width") and isinstance(e.value, m.Number)
           and float(e.value.value) > 0}
    if len(box) == 1:
        (given, entry), = box.items()
        other = "width" if given == "length" else "length"
        ctx.report("bad-property-value", f"a box footprint needs both length and width: give '{other}: N;' too "
                   f"(or neither, for the disc of 'radius')", entry.span)


def footprint(system: m.System) -> RobotConfig:
    """The body its `body { }` block declares, from the values check_body accepts (the others, which
    it reports, at the simulator's defaults)."""
    values = {e.name: e.value.value for e in (system.body.entries if system.body is not None else ())
              if e.name in BODY_KEYS and isinstance(e.value, m.Number)
              and body_problem(e.name, float(e.value.value)) is None}
    return RobotConfig.from_spec(system.name, values)


def check_worlds(ctx: Context, system: m.System) -> dict[str, m.Setting]:
    """The system's worlds by name; each a TOML world file the simulator can load."""
    entries = system.worlds.entries if system.worlds is not None else ()
    ctx.duplicates(entries, "world")
    worlds = first_by_name(entries)
    for entry in entries:
        if not isinstance(entry.value, m.String):
            ctx.report("bad-property-value", f"world '{entry.name}' is a world file: give its path in quotes, "
                       "relative to this spec", entry.value.span)
            continue
        path = ctx.base_dir(entry.span) / entry.value.value
        try:
            found = path.is_file()
        except OSError:  # a name longer than the file system allows names no file
            found = False
        if not found:
            ctx.report("missing-world", f"world file '{entry.value.value}' not found (looked at {path})",
                       entry.value.span)
            continue
        try:
            body = footprint(system)
            overlap = load_world(path).start_overlap(body.radius, body.length, body.width)
            if overlap is not None:
                ctx.report("bad-world", f"{entry.value.value}: {overlap}", entry.value.span)
        except WorldError as error:  # each problem, named as the spec names the file, not by this machine's folders
            for problem in error.problems:
                ctx.report("bad-world", problem.replace(str(path), entry.value.value), entry.value.span)
    return worlds


def check_missions(ctx: Context, system: m.System, worlds: dict[str, m.Setting]) -> None:
    ctx.duplicates(system.missions, "mission")
    supervisor = ctx.named(m.Procedures).get(system.supervisor.text) if system.supervisor else None
    goals = achievable_goals(supervisor) if supervisor is not None else {}
    needs = numeric_positions(supervisor) if supervisor is not None else {}
    for node in walk(supervisor) if supervisor is not None else ():  # the KAs' own subgoals of constants
        if isinstance(node, m.Goal) and node.op == "!":
            check_numeric_arguments(ctx, node.body, needs)
    for mission in system.missions:
        if mission.world is not None:
            if mission.world.text not in worlds:
                ctx.unknown("undefined-world", "world", mission.world.text, worlds, mission.world.span,
                            f" of system '{system.name}'")
        elif len(worlds) != 1:
            ctx.report("missing-property", f"mission '{mission.name}' needs 'world: NAME;' (system '{system.name}' "
                       f"has {len(worlds)} worlds{': ' + ', '.join(worlds) if worlds else ''})", mission.span)
        if mission.horizon is not None and mission.horizon.seconds <= 0:
            ctx.report("bad-duration", "a mission's horizon must be longer than zero", mission.horizon.span)
        if not mission.goals and mission.plan is None:
            ctx.report("missing-property", f"mission '{mission.name}' asks nothing: give it 'goal: !(...);' or "
                       "'plan: <mission of the ftplan block>;'", mission.span)
        for goal in mission.goals:
            if system.supervisor is None:
                ctx.report("goal-without-supervisor", f"mission '{mission.name}' posts a goal, but system "
                           f"'{system.name}' has no supervisor to achieve it: give it 'supervisor: NAME;'", goal.span)
            elif supervisor is not None:
                check_mission_goal(ctx, goal, goals, supervisor.name, supervisor.predicates)
                check_goal_values(ctx, goal, supervisor, needs)


def check_planning(ctx: Context, system: m.System, supervisor: m.Procedures | None,
                   executive: m.Executive | None) -> None:
    """Missions FTplan plans name the ftplan block's missions; every task its planners may put in a
    plan is bound to a goal, a service or a request that takes its arguments."""
    ftplan = ctx.named(m.FtPlan).get(system.planning.text) if system.planning is not None else None
    bindings = system.bindings.entries if system.bindings is not None else ()
    for mission in system.missions:
        if mission.plan is None:
            continue
        if system.planning is None:
            ctx.report("missing-property", f"mission '{mission.name}' is planned, but system '{system.name}' has "
                       "no planning: give it 'planning: <ftplan block>;'", mission.plan.span)
        elif ftplan is not None and mission.plan.text not in {m_.name for m_ in ftplan.missions}:
            ctx.unknown("undefined-mission", "mission", mission.plan.text, {m_.name for m_ in ftplan.missions},
                        mission.plan.span, f" of ftplan '{ftplan.name}'")
    if system.planning is None:
        for binding in bindings[:1]:
            ctx.report("missing-property", f"system '{system.name}' binds tasks but plans nothing: give it "
                       "'planning: <ftplan block>;'", binding.span)
        return
    if ftplan is None:
        return
    ctx.duplicates(bindings, "binding of task", key="task")
    tasks = planned_tasks(ctx, ftplan)
    bound = {b.task for b in bindings}
    for task in tasks.tasks.values():
        if task.name not in bound:
            ctx.report("missing-binding", f"task '{task.name}' of the planners' domains has no binding: say how it "
                       f"is carried out in system '{system.name}''s 'bindings {{ {task.name}(...) => goal "
                       "G(...); }'", (system.bindings or system).span)
    goals = achievable_goals(supervisor) if supervisor is not None else {}
    services = ctx.symbols.services_of(executive) if executive is not None else {}
    reports = {u.task: len(u.args) for u in ftplan.state_updates if u.report == "report"}
    domains = planner_tables(ctx, ftplan)
    for binding in bindings:
        check_task(ctx, tasks, binding.task, binding.span, binding.args)
        plain = tuple(a for a in binding.target_args if not isinstance(a, m.IxCall))
        # `ATTR(...)`: FTplan's state after the action, an attribute of its vocabulary
        after = [a for a in binding.target_args if isinstance(a, m.IxCall)]
        for call in after:
            check_attribute(ctx, tasks, call.function, len(call.args), call.span)
        inner = tuple(x for call in after for x in call.args)
        # `where ATTR(?o, ...) := VALUE` binds the ?variables of its pattern too
        where = binding.where
        binders: tuple[m.IxExpr, ...] = binding.args
        if where is not None:
            check_attribute(ctx, tasks, where.attribute, len(where.args), where.span)
            check_terms(ctx, (*where.args, where.value))
            binders = (*binding.args, *where.args)
            check_bound(ctx, binders, (where.value,), f"task '{binding.task}'")
        check_terms(ctx, (*binding.args, *plain, *inner))
        check_bound(ctx, binders, (*plain, *inner), f"task '{binding.task}'")
        check_binding_target(ctx, system, binding, goals, services, domains)
        if binding.kind == "goal" and supervisor is not None:
            check_goal_binding_values(ctx, domains, supervisor, binding)
        if binding.report is not None:
            check_binding_report(ctx, binding.report, reports)


def check_goal_binding_values(ctx: Context, domains: Mapping[str, DomainTables], supervisor: m.Procedures,
                              binding: m.Binding) -> None:
    """A task's parameter passed to a goal (`TRAVEL(?a, ?b) => goal GO-ROOM(?b)`) may take only
    values the goal's predicate declares there: the planners' domains give its values, and one
    outside the predicate's domain makes such an action fail at run time, before any service."""
    declared = next((p for p in supervisor.predicates if p.name == binding.target.text), None)
    if declared is None or len(declared.params) != len(binding.target_args):
        return
    names = [a.name if isinstance(a, m.IxVar) else None for a in binding.args]
    predicate_domains = Domains(supervisor)
    for position, arg in enumerate(binding.target_args):
        if not isinstance(arg, m.IxVar) or arg.name not in names:
            continue
        allowed = predicate_domains.values(declared.params[position].domain)
        values = task_parameter_values(domains, binding.task, names.index(arg.name))
        if allowed is None or values is None:
            continue
        outside = sorted(values - {str(v) for v in allowed})
        if outside:
            ctx.warn("value-outside-domain", f"{arg.name} of task '{binding.task}' may be {', '.join(outside)}, "
                     f"which {declared.name}'s '{declared.params[position].name}' does not hold "
                     f"({', '.join(str(v) for v in allowed)}): such an action's goal fails at run time; pass what "
                     "the goal takes, or widen its domain", arg.span)


def task_parameter_values(domains: Mapping[str, DomainTables], task_name: str, position: int) -> set[str] | None:
    """The symbols the task's parameter at `position` may take, in every planner's domain (None
    when one does not say them as a set of symbols)."""
    values: set[str] = set()
    for found in domains.values():
        task = found.tasks.get(task_name)
        if task is None or position >= len(task.params):
            continue
        said = found.value_domain(task, task.params[position].name)
        if said is None:
            return None
        values |= said
    return values


def check_binding_target(ctx: Context, system: m.System, binding: m.Binding, goals: dict[str, int],
                         services: Mapping[str, m.Service], domains: Mapping[str, DomainTables]) -> None:
    target, given = binding.target, len(binding.target_args)
    if binding.kind == "goal":
        if system.supervisor is None:
            ctx.report("goal-without-supervisor", f"task '{binding.task}' is carried out as a goal, but system "
                       f"'{system.name}' has no supervisor: give it 'supervisor: NAME;'", target.span)
        elif target.text not in goals:
            ctx.unknown("undefined-goal", "goal", target.text, goals, target.span, " (no KA is invoked by it)")
        elif goals[target.text] != given:
            ctx.report("arity-mismatch", f"'{target.text}' takes {goals[target.text]} argument(s), {given} given",
                       target.span)
    elif binding.kind == "service":
        service = services.get(target.text)
        if system.executive is None:
            ctx.report("undefined-service", f"task '{binding.task}' is carried out by a service, but system "
                       f"'{system.name}' has no executive: give it 'executive: NAME;'", target.span)
        elif service is None:
            ctx.unknown("undefined-service", "service", target.text, services, target.span)
        elif len(service.takes) != given:
            ctx.report("arity-mismatch", f"service '{service.name}' takes {len(service.takes)} input(s) "
                       f"({', '.join(t.text for t in service.takes) or 'none'}), {given} given", target.span)
        else:
            inputs = request_inputs(ctx, service)
            check_constant_inputs(ctx, binding, [inputs.get(t.text) for t in service.takes],
                                  f"service '{service.name}'", service.request.parts[0] if service.request else "",
                                  domains)
    else:
        request = resolve_request(ctx, target)
        module_name = target.parts[0]
        users = sorted(name for name, service in services.items()
                       if service.request is not None and service.request.parts[0] == module_name)
        if request is not None and users:
            ctx.warn("bypasses-executive", f"'{target.text}' goes to module '{module_name}' past the executive, "
                     f"whose service(s) {', '.join(users)} use that module: their conflicts do not hold against "
                     "this request, and `specc verify` does not cover it; bind a service of the executive instead "
                     "(=> service NAME(...))", target.span)
        if request is not None and len(request.inputs) != given:
            ctx.report("arity-mismatch", f"request '{target.text}' takes {len(request.inputs)} input(s) "
                       f"({', '.join(i.name for i in request.inputs) or 'none'}), {given} given", target.span)
        elif request is not None:
            check_constant_inputs(ctx, binding, list(request.inputs), f"request '{target.text}'",
                                  target.parts[0], domains)


def check_constant_inputs(ctx: Context, binding: m.Binding, inputs: list[m.TypedName | None],
                          target: str, module_name: str, domains: Mapping[str, DomainTables]) -> None:
    """Each value a binding's argument may give must be one of the input it gives: a constant
    (`service REPORT(FAST)`), or each symbol a task's parameter may take in the planners' domains
    (`LOOK(?p) => service SET-LEVEL(?p)`, ?p a place, the input a number). The request refuses
    it at run time, at every replanning. Enums are the request's module's (two modules may each
    have an enum of one name)."""
    enums = module_enums(ctx, module_name)
    names = [a.name if isinstance(a, m.IxVar) else None for a in binding.args]
    for arg, typed in zip(binding.target_args, inputs, strict=False):
        if typed is None or typed.type.size is not None:
            continue
        if isinstance(arg, m.IxVar) and arg.name in names:
            # A task parameter's symbols (numbers, or a domain not written as symbols, pass).
            values: list[str | float] = sorted(task_parameter_values(domains, binding.task, names.index(arg.name))
                                               or ())
            said, fix = f"{arg.name} of task '{binding.task}' may be {{}}, which", (
                ": pass a parameter whose domain holds only such values, or a constant")
        elif isinstance(arg, m.Number | m.IxName):
            values, said, fix = [arg.value if isinstance(arg, m.Number) else arg.name], "{}", ""
        else:
            continue
        kind = typed.type.name
        refused = refused_values(kind, values, enums)
        if refused:
            allowed = f" ({', '.join(sorted(enums[kind]))})" if kind in enums else ""
            shown = said.format(", ".join(str(v) for v in refused))
            ctx.report("bad-argument-type", f"{shown} cannot be input '{typed.name}' of {target}, of type "
                       f"{kind}{allowed}{fix}", arg.span)


def check_binding_report(ctx: Context, report: m.BindingReport, reports: dict[str, int]) -> None:
    """A report FTplan's state rules read (`on report NAME(...)`), of posters that exist."""
    if report.name not in reports:
        ctx.unknown("undefined-report", "report", report.name, reports, report.span,
                    " (no `on report` rule of the ftplan block reads it)")
    elif reports[report.name] != len(report.values):
        ctx.report("arity-mismatch", f"the state rules read {report.name} with {reports[report.name]} value(s), "
                   f"{len(report.values)} given", report.span)
    for value in report.values:
        if len(value.parts) < 3:
            ctx.report("bad-reference", f"'{value.text}' should be written module.Poster.field", value.span)
        else:
            resolve_poster(ctx, value)


def achievable_goals(procedures: m.Procedures) -> dict[str, int]:
    """The goals a KA of `procedures` is invoked by, with their arity."""
    goals: dict[str, int] = {}
    for ka in procedures.kas:
        if isinstance(ka.invocation, m.Goal):
            goals.setdefault(ka.invocation.body.head, len(ka.invocation.body.args))
    return goals


def check_mission_goal(ctx: Context, goal: m.Goal, goals: dict[str, int], procedures: str,
                       predicates: Sequence[m.PredicateDecl] = ()) -> None:
    if goal.op not in MISSION_GOAL_OPS:
        ctx.report("bad-mission-goal", f"a mission asks to achieve '!(...)', tests '?(...)' or states a fact its "
                   f"supervisor knows from the start '=>(...)', not '{goal.op}(...)'", goal.span)
        return
    for node in walk(goal):
        if isinstance(node, m.LogicVar | m.ProgramVar):
            ctx.report("unbound-variable", f"'{node.name}' has no value in a mission: give a constant", node.span)
    body = goal.body
    if goal.op == "=>":  # a fact: of a predicate the procedures declare
        declared = {p.name: len(p.params) for p in predicates}
        if body.head not in declared:
            ctx.report("undefined-predicate", f"procedures '{procedures}' declare no predicate '{body.head}' for "
                       f"'=>({body.head} ...)' to state{did_you_mean(body.head, declared)}: declare it with "
                       "'predicate'", body.span)
        elif declared[body.head] != len(body.args):
            ctx.report("arity-mismatch", f"'{body.head}' takes {declared[body.head]} argument(s), {len(body.args)} "
                       "given", body.span)
        return
    if goal.op == "?":  # a test reads the database: a predicate the procedures declare, or a goal's
        declared = {p.name: len(p.params) for p in predicates} | goals
        if body.head not in declared:
            ctx.report("undefined-predicate", f"procedures '{procedures}' declare no predicate '{body.head}' for "
                       f"'?({body.head} ...)' to test{did_you_mean(body.head, declared)}", body.span)
        elif declared[body.head] != len(body.args):
            ctx.report("arity-mismatch", f"'{body.head}' takes {declared[body.head]} argument(s), {len(body.args)} "
                       "given", body.span)
        return
    if goal.op == "!" and body.head not in goals:
        ctx.report("undefined-goal", f"no KA of procedures '{procedures}' is invoked by '!({body.head} ...)'"
                   f"{did_you_mean(body.head, goals)}", body.span)
    elif goal.op == "!" and goals[body.head] != len(body.args):
        ctx.report("arity-mismatch", f"'{body.head}' takes {goals[body.head]} argument(s), {len(body.args)} given",
                   body.span)


def check_goal_values(ctx: Context, goal: m.Goal, procedures: m.Procedures,
                      needs: Mapping[tuple[str, int], NumberNeed]) -> None:
    """A mission's constant arguments lie in the finite domains the goal's predicate declares, and
    a symbol (a number with a fraction) never stands where every KA the goal invokes needs a
    number (a whole number): `needs`, the procedures' `numeric_positions`."""
    for position, arg in enumerate(goal.body.args):
        value = arg.value if isinstance(arg, m.Number | m.String) else arg.text if isinstance(arg, m.Ref) else None
        shown = f'"{arg.value}"' if isinstance(arg, m.String) else None  # a string, not the symbol it spells
        outside = argument_outside(procedures, goal.body.head, position, value, shown)
        if outside is not None:  # the same words and code as the same mistake in a KA
            ctx.report("value-outside-domain", outside, arg.span)
            continue
        problem = number_problem(needs, goal.body.head, position, value, shown)
        if problem is not None:
            ctx.report("bad-argument", problem, arg.span)


def goal_argument_problem(procedures: m.Procedures, needs: Mapping[tuple[str, int], NumberNeed], head: str,
                          position: int, value: object) -> str | None:
    """Why `value` cannot stand at `position` among the arguments of a goal `head` (None when it
    can, or nothing says): outside the finite domain the predicate declares there, or not the
    number every KA the goal invokes passes it on to (`needs`). For a mission's goal and for
    `specc run --goal` alike."""
    return argument_outside(procedures, head, position, value) or number_problem(needs, head, position, value)


def argument_outside(procedures: m.Procedures, head: str, position: int, value: object,
                     shown: str | None = None) -> str | None:
    """Why `value` (written `shown`), at `position` among the arguments of a goal `head`, lies
    outside the finite domain the predicate declares there (None when it lies inside, or nothing
    says); in the words a KA's argument outside it gets."""
    declared = next((p for p in procedures.predicates if p.name == head), None)
    if declared is None or position >= len(declared.params) or value is None:
        return None
    param = declared.params[position]
    allowed = Domains(procedures).values(param.domain)
    if allowed is None or value in allowed:
        return None
    listed = ", ".join(str(v) for v in allowed) if len(allowed) <= 12 else describe_domain(param.domain)
    return (f"'{shown or value}' is not in the domain of {declared.name}'s '{param.name}' ({listed})"
            f"{did_you_mean(str(value), [str(v) for v in allowed])}")


def number_problem(needs: Mapping[tuple[str, int], NumberNeed], head: str, position: int,
                   value: object, shown: str | None = None) -> str | None:
    """Why `value` (written `shown`) cannot go where the goal's KAs pass argument `position` on to
    a number: a symbol or a string, or a number with a fraction where a whole one is needed (None
    when it can)."""
    need = needs.get((head, position))
    if need is None or value is None:
        return None
    where = f"argument {position + 1} of {head} reaches {need.reason}"
    if not isinstance(value, int | float) or isinstance(value, bool):
        return f"{shown or value} is not a number: {where}"
    if need.whole and not float(value).is_integer():
        return f"{shown or value} is not a whole number: {where}"
    return None


def check_numeric_arguments(ctx: Context, goal: m.SExp, needs: Mapping[tuple[str, int], NumberNeed]) -> None:
    """`bad-argument` for a constant the goal's KAs cannot pass on to the number they need."""
    for position, arg in enumerate(goal.args):
        value = arg.value if isinstance(arg, m.Number) else arg.text if isinstance(arg, m.Ref) else \
            repr(arg.value) if isinstance(arg, m.String) else None
        problem = number_problem(needs, goal.head, position, value)
        if problem is not None:
            ctx.report("bad-argument", problem, arg.span)


@dataclass(frozen=True)
class NumberNeed:
    """A goal argument every KA of the goal passes on to a number: the parameter it reaches, said
    for messages, and whether that number must be whole (an `int` parameter)."""

    reason: str
    whole: bool


def numeric_positions(procedures: m.Procedures) -> dict[tuple[str, int], NumberNeed]:
    """The (goal head, argument position) that every KA invoked by the head passes on to a number:
    a primitive action's parameter of a numeric domain, or such a position of a subgoal; with the
    parameter reached (for the message). A fixed point over the KAs, as a goal's KAs call goals."""
    actions = {a.name: a for a in procedures.actions}
    kas: dict[str, list[m.KA]] = {}
    for ka in procedures.kas:
        if isinstance(ka.invocation, m.Goal) and ka.invocation.op == "!":
            kas.setdefault(ka.invocation.body.head, []).append(ka)
    found: dict[tuple[str, int], NumberNeed] = {}

    def reached(ka: m.KA, var: str) -> NumberNeed | None:
        """What numeric parameter `var` of `ka` is passed to, if any."""
        if ka.action is not None:
            action = actions.get(ka.action.call.head)
            for arg, param in zip(ka.action.call.args, action.params if action is not None else (), strict=False):
                kind = domain_kind(procedures, param.domain)
                if isinstance(arg, m.LogicVar) and arg.name == var and kind in ("int", "number"):
                    return NumberNeed(f"'{param.name}' ({describe_domain(param.domain)}) of action "
                                      f"{ka.action.call.head}", kind == "int")
        for node in walk(ka.body) if ka.body is not None else ():
            if isinstance(node, m.Goal) and node.op == "!":
                for position, arg in enumerate(node.body.args):
                    if isinstance(arg, m.LogicVar) and arg.name == var and (node.body.head, position) in found:
                        return found[(node.body.head, position)]
        return None

    changed = True
    while changed:
        changed = False
        for head, invoked in kas.items():
            for position in range(max(len(ka.invocation.body.args) for ka in invoked  # type: ignore[union-attr]
                                      )):
                if (head, position) in found:
                    continue
                reasons = []
                for ka in invoked:
                    args = ka.invocation.body.args  # type: ignore[union-attr]
                    arg = args[position] if position < len(args) else None
                    reason = reached(ka, arg.name) if isinstance(arg, m.LogicVar) else None
                    if reason is None:
                        break
                    reasons.append(reason)
                else:
                    found[(head, position)] = NumberNeed(reasons[0].reason, all(r.whole for r in reasons))
                    changed = True
    return found


def check_service_actions(ctx: Context, procedures: m.Procedures, executives: list[m.Executive],
                          without: str) -> None:
    """Each action bound to a service gives it the inputs it `takes`, in number and type."""
    for action in procedures.actions:
        binding = action.binding
        if not isinstance(binding, m.ServiceBinding):
            continue
        if not executives:
            ctx.report("undefined-service", f"action '{action.name}' requests service '{binding.service}', but "
                       f"{without}", binding.span)
            continue
        services = ctx.symbols.offered
        service = services.get(binding.service)
        if service is None:
            ctx.unknown("undefined-service", "service", binding.service, services, binding.span,
                        f" (action '{action.name}' requests it)")
            continue
        if len(action.params) != len(service.takes):
            taken = ", ".join(t.text for t in service.takes) or "nothing"
            ctx.report("arity-mismatch", f"service '{service.name}' takes {len(service.takes)} input(s) ({taken}); "
                       f"action '{action.name}' gives {len(action.params)}", action.span)
            continue
        inputs = request_inputs(ctx, service)
        for param, taken_input in zip(action.params, service.takes, strict=True):
            typed = inputs.get(taken_input.text)
            if typed is not None:
                check_argument_type(ctx, procedures, param, typed, service.name,
                                    service.request.parts[0] if service.request else "")


def check_executive_goals(ctx: Context, procedures: m.Procedures, executives: list[m.Executive], without: str,
                          missions: tuple[m.Node, ...] = ()) -> None:
    """The goals of an executive KA (`property: executive`, the request protocol of Fig 4.3) name
    a service first: a constant there must be one the executive offers, or the request is answered
    BAD-SERVICE at run time and `specc verify --goal` stops at it."""
    # Each head's executive KAs, and the services they serve when every one names its service (a
    # KA per service, `!(EXEC STOW $R)`); None when one serves any (`!(EXEC $S $R)`).
    protocols: dict[str, m.KA] = {}
    served: dict[str, set[str] | None] = {}
    for ka in procedures.kas:
        if "executive" in ka.properties and isinstance(ka.invocation, m.Goal) and ka.invocation.body.args:
            head = ka.invocation.body.head
            protocols[head] = ka
            service, names = _service_name(ka.invocation.body.args[0]), served.setdefault(head, set())
            if names is not None:
                served[head] = None if service is None else names | {service}
    if not protocols:
        return
    if not executives:
        first = next(iter(protocols.values()))
        ctx.warn("no-executive", f"KA '{first.name}' is the executive's request protocol, but {without}", first.span)
        return
    services = ctx.symbols.offered
    for root in (procedures, *missions):
        for node in walk(root):
            if not (isinstance(node, m.Goal) and node.op == "!" and node.body.head in protocols):
                continue
            named = node.body.args[0]
            which = f"executive '{executives[0].name}' does not offer" if len(executives) == 1 \
                else "no executive offers"
            name = _service_name(named)
            kas_serve = served.get(node.body.head)
            if name is not None and kas_serve is not None and name not in kas_serve:
                ctx.warn("no-applicable-ka", f"goal {node.body.head} asks for service '{name}', but no executive KA "
                           f"serves it (those of {node.body.head} serve {', '.join(sorted(kas_serve))}): no KA "
                           f"applies and the goal fails; write a KA invoked by !({node.body.head} {name} ...)",
                           named.span)
            elif name is not None and name not in services:
                ctx.warn("undefined-service", f"goal {node.body.head} asks for service '{name}', which "
                         f"{which}{did_you_mean(name, services)}: it will be answered BAD-SERVICE", named.span)
            elif isinstance(named, m.Number):  # a value where the protocol's goal names the service
                ctx.warn("undefined-service", f"goal {node.body.head} names the service first (KA "
                         f"'{protocols[node.body.head].name}' is the executive's request protocol), not "
                         f"{named.value}, which {which} (services: {', '.join(sorted(services))}): it will be "
                         "answered BAD-SERVICE", named.span)


def _service_name(arg: m.SArg) -> str | None:
    """The service a request's first argument names: a name, or a string (the service's name too,
    once compiled: `"AVOID-ON"`); None for a variable or a number."""
    return arg.text if isinstance(arg, m.Ref) else arg.value if isinstance(arg, m.String) else None


def request_inputs(ctx: Context, service: m.Service) -> dict[str, m.TypedName]:
    request = ctx.symbols.service_request(service)
    return {i.name: i for i in request.inputs} if request is not None else {}


def check_argument_type(ctx: Context, procedures: m.Procedures, param: m.PParam, typed: m.TypedName,
                        service: str, module_name: str) -> None:
    """A PRS parameter's domain must hold only values the request's input can take."""
    kind = domain_kind(procedures, param.domain)
    input_type = typed.type.name
    if typed.type.size is not None:
        accepted = False
    elif input_type in NUMERIC_INPUTS:
        accepted = kind in ("int", "number")
    elif input_type in WHOLE_INPUTS:
        accepted = kind == "int"
    elif input_type in TEXT_INPUTS:
        accepted = kind in ("symbol", "int", "number")  # a symbol or a number, written as text
    elif input_type == "bool":
        accepted = kind == "symbol" and symbols(procedures, param.domain) <= {"true", "false", "TRUE", "FALSE"}
    else:
        enum = module_enums(ctx, module_name).get(input_type)
        structs = {s.name for module in ctx.items(m.Module) if module.name == module_name for s in module.structs}
        if enum is None and input_type not in structs:
            return  # a type no module declares: `undefined-type` said so where it is written
        accepted = enum is not None and kind == "symbol" and bool(symbols(procedures, param.domain)) \
            and symbols(procedures, param.domain) <= enum
    if not accepted:
        ctx.report("bad-argument-type", f"'{param.name}' ({describe_domain(param.domain)}) cannot be service "
                   f"'{service}''s input '{typed.name}' of type {input_type}"
                   f"{'[' + str(typed.type.size) + ']' if typed.type.size is not None else ''}", param.span)


def domain_kind(procedures: m.Procedures, domain: m.PDomain, seen: frozenset[str] = frozenset()) -> str:
    """int (whole numbers), number, symbol, or unknown."""
    if isinstance(domain, m.IntRange):
        return "int"
    if isinstance(domain, m.SymbolSet):
        numeric = all(_is_number(v) for v in domain.values)
        return ("int" if all(v.lstrip("-").isdigit() for v in domain.values) else "number") if numeric else \
            "symbol" if not any(_is_number(v) for v in domain.values) else "unknown"
    if domain.name in ("int",):
        return "int"
    if domain.name in ("float", "number"):
        return "number"
    if domain.name in TEXT_DOMAINS:
        return "symbol"
    declared = next((t.domain for t in procedures.types if t.name == domain.name), None)
    if declared is None or domain.name in seen:
        return "unknown"
    return domain_kind(procedures, declared, seen | {domain.name})


def symbols(procedures: m.Procedures, domain: m.PDomain, seen: frozenset[str] = frozenset()) -> set[str]:
    if isinstance(domain, m.SymbolSet):
        return set(domain.values)
    if isinstance(domain, m.DomainRef) and domain.name not in seen:
        declared = next((t.domain for t in procedures.types if t.name == domain.name), None)
        return symbols(procedures, declared, seen | {domain.name}) if declared is not None else set()
    return set()


def describe_domain(domain: m.PDomain) -> str:
    if isinstance(domain, m.SymbolSet):
        return "{" + ", ".join(domain.values) + "}"
    if isinstance(domain, m.IntRange):
        return f"{domain.low}..{domain.high}"
    return domain.name


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True
