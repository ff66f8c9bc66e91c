"""Codel names exist in the module's declared Python codel module (read, never executed)."""

from __future__ import annotations

from collections.abc import Mapping

from specc.check.context import Context
from specc.diagnostics import did_you_mean, display_path
from specc.model import nodes as m
from specc.model.span import Span
from specc.pysource import FunctionShape, find_module, top_level_functions

# How the runtime calls each kind of user function: the arguments it passes.
REQUEST_CODEL = ("sdi", "request")
TASK_CODEL = ("sdi",)
# What any request codel may return besides its request's codel states and fail messages.
CODEL_ENDINGS = frozenset({"ether", "zombie"})
# What a validate codel may return to accept its request (or a fail message to refuse it).
VALIDATE_ACCEPTS = frozenset({"end", "ok", "OK", "ether", "exec"})


def check(ctx: Context) -> None:
    posters = {module.name: {p.name for p in module.posters} for module in ctx.items(m.Module)}
    requests = {module.name: {r.name for r in module.requests} for module in ctx.items(m.Module)}
    for module in ctx.items(m.Module):
        used: list[tuple[str, Span]] = []
        for request in module.requests:
            used += [(c.function, c.span) for c in request.codels]
            if request.validate is not None:
                used.append((request.validate.text, request.validate.span))
        for task in module.exec_tasks:
            used += [(c.function, c.span) for c in task.codels]
        if module.codel_module is None:
            if used:
                ctx.report("missing-property",
                           f"module '{module.name}' names codels but no 'codels: \"python.module\";' to find them",
                           module.span)
            continue
        functions = python_functions(ctx, module.codel_module)
        if functions is None:
            continue
        for name, span in used:
            if name not in functions:
                ctx.report("undefined-codel",
                           f"codel '{name}' is not defined in {module.codel_module.value}"
                           f"{did_you_mean(name, functions)}; `specc skeleton` can write a stub for it", span)
        where = module.codel_module.value
        for request in module.requests:
            fail = {f.text for f in request.fail}
            states = {c.state for c in request.codels} | {"end"}
            for codel in request.codels:
                shape = functions.get(codel.function)
                check_call(ctx, codel.function, shape, REQUEST_CODEL, where, codel.span)
                if codel.state != "inter":  # whatever an interruption codel returns but `inter` ends it
                    allowed = CODEL_ENDINGS | fail | (set(codel.yields) if codel.yields else states)
                    if codel.state == "end":
                        allowed |= {"end"}  # the end codel returning "end" ends the activity, declared or not
                    check_returns(ctx, codel.function, shape, allowed, where, codel.span,
                                  f"codel '{codel.state}' of request {request.name}")
            if request.validate is not None:
                shape = functions.get(request.validate.text)
                check_call(ctx, request.validate.text, shape, REQUEST_CODEL, where, request.validate.span)
                check_returns(ctx, request.validate.text, shape, VALIDATE_ACCEPTS | fail, where,
                              request.validate.span, f"the validate codel of request {request.name}")
        for task in module.exec_tasks:
            for codel in task.codels:
                check_call(ctx, codel.function, functions.get(codel.function), TASK_CODEL, where, codel.span)
        for name, span in dict(used).items():
            check_poster_reads(ctx, name, functions.get(name), posters, where, span)
        for request in module.requests:
            check_sends(ctx, module, request, functions, requests, where)


def check_sends(ctx: Context, module: m.Module, request: m.Request, functions: Mapping[str, FunctionShape | None],
                requests: Mapping[str, set[str]], where: str) -> None:
    """Each request a codel of `request` sends by a written name (`sdi.send_request("ptu.Sweep")`)
    exists, and the request's `sends:` lists it: the incompatibility graph and `specc verify`
    know a codel's sends from that line only, so one left out is a send whose effect (another
    module's activity interrupted) nothing they prove covers."""
    declared = {ref.text for ref in request.sends}
    codels = [(c.function, c.span) for c in request.codels]
    if request.validate is not None:
        codels.append((request.validate.text, request.validate.span))
    said: set[str] = set()
    # With an entry of `sends:` naming no request, that error is the one to fix first: no
    # undeclared-send for the request it meant.
    declared_resolve = all(sent in requests.get(other, ())
                           for other, _, sent in (ref.text.partition(".") for ref in request.sends))
    for name, span in codels:
        shape = functions.get(name)
        for line in shape.computed_sends if shape is not None else ():
            assert shape is not None
            ctx.warn("computed-send", f"codel '{name}' sends a request whose name it computes "
                     f"({place(shape, where, line)}): neither the incompatibility graph nor `specc verify` can "
                     "tell which, so what they prove may not hold of the robot; write the name as a string "
                     "(`sdi.send_request(\"module.Request\")`) and list it in the request's 'sends:'", span)
        for target, line in shape.sends if shape is not None else ():
            if target in declared or target in said:
                continue
            said.add(target)
            assert shape is not None
            other, _, sent = target.partition(".")
            if sent not in requests.get(other, ()):
                known = [f"{o}.{r}" for o, names in requests.items() for r in names]
                ctx.warn("undefined-request", f"codel '{name}' sends '{target}' ({place(shape, where, line)}), but no "
                         f"module has that request{did_you_mean(target, known)}: the send fails at run time", span)
            elif declared_resolve:
                ctx.warn("undeclared-send", f"codel '{name}' of request {module.name}.{request.name} sends '{target}' "
                         f"({place(shape, where, line)}), which the request's 'sends:' does not list: the "
                         f"incompatibility graph and `specc verify` leave that send out, so what they prove may not "
                         f"hold of the robot; add 'sends: {target};' to request {request.name}", request.span)


def check_poster_reads(ctx: Context, name: str, shape: FunctionShape | None, posters: dict[str, set[str]],
                       where: str, span: Span) -> None:
    """Each poster a codel reads by a written name (`sdi.read_poster("arm.State")`) is one a module
    exports: a misspelt one reads None at run time, which the codel takes for "not yet"."""
    for poster, line in shape.posters if shape is not None else ():
        module, _, exported = poster.partition(".")
        assert shape is not None
        if module not in posters:
            ctx.warn("undefined-module", f"codel '{name}' reads poster '{poster}' ({place(shape, where, line)}), "
                     f"but no module is named '{module}'{did_you_mean(module, posters)}: it reads None", span)
        elif exported not in posters[module]:
            known = posters[module]
            ctx.warn("undefined-poster", f"codel '{name}' reads poster '{poster}' ({place(shape, where, line)}), which "
                     f"module '{module}' does not export{did_you_mean(exported, known)} (its posters: "
                     f"{', '.join(sorted(known)) or 'none'}): it reads None", span)


def check_call(ctx: Context, name: str, shape: FunctionShape | None, call: tuple[str, ...], where: str,
               span: Span) -> None:
    """The function can be called as the runtime calls it (read from its `def`, never run)."""
    if shape is None or shape.accepts(len(call)):
        return
    if shape.not_callable:
        ctx.report("bad-codel-signature", f"'{name}' ({place(shape, where, shape.line)}) is {shape.not_callable}, "
                   f"not a function: the runtime calls it as {name}({', '.join(call)}); define it with "
                   f"`def {name}({', '.join(call)}):`", span)
        return
    if shape.most is not None and shape.most < 0:
        takes = "a keyword-only argument without default"
    elif shape.most is None:
        takes = f"at least {shape.least} argument(s)"
    else:
        takes = f"{shape.least}" + (f" to {shape.most}" if shape.most != shape.least else "") + " argument(s)"
    ctx.report("bad-codel-signature", f"'{name}' ({place(shape, where, shape.line)}) takes {takes}, but it is "
               f"called as {name}({', '.join(call)}): give it {len(call)} parameter(s)", span)


def place(shape: FunctionShape, where: str, line: int) -> str:
    """Where a line of the function is: in the module the spec names, or, for a function that
    module re-exports, in the file it is written in."""
    if shape.defined_in:
        return f"{shape.defined_in}, line {line}, re-exported by {where}"
    return f"{where}, line {line}"


def check_returns(ctx: Context, name: str, shape: FunctionShape | None, allowed: set[str] | frozenset[str],
                  where: str, span: Span, what: str) -> None:
    """Every string the function returns as it is written is one the runtime accepts there."""
    for value, line in shape.returns if shape is not None else ():
        if value not in allowed:
            close = did_you_mean(value, allowed)
            fix = close or f"; a new failure is declared with 'fail: {value};'"
            assert shape is not None
            ctx.report("undeclared-result", f"'{name}' returns {value!r} ({place(shape, where, line)}), which {what} "
                       f"does not declare (it may return {', '.join(sorted(allowed))}){fix}", span)


def python_functions(ctx: Context, dotted: m.String) -> Mapping[str, FunctionShape | None] | None:
    """The functions of a user Python module named in the spec; None (reported) if unreadable."""
    if not all(part.isidentifier() for part in dotted.value.split(".")):
        ctx.report("bad-python-module", f"'{dotted.value}' is not a Python module name: give dotted identifiers, "
                   "like \"cart_codels\" or \"cart_codels.drive\"", dotted.span)
        return None
    path = find_module(dotted.value, ctx.base_dir(dotted.span))
    if path is None:
        ctx.report("missing-python-module",
                   f"Python module '{dotted.value}' not found next to the spec (looked for "
                   f"{dotted.value.replace('.', '/')}.py from {ctx.base_dir(dotted.span)} upwards); `specc "
                   "skeleton` writes it with a stub for every codel the specs name", dotted.span)
        return None
    functions = top_level_functions(path)
    if isinstance(functions, OSError):
        ctx.report("unreadable-file", f"cannot read Python module '{dotted.value}' ({display_path(path)}): "
                   f"{functions.strerror or functions}; give the file read permission", dotted.span)
        return None
    if isinstance(functions, SyntaxError):
        ctx.report("python-syntax-error",
                   f"{display_path(path)}:{functions.lineno}: Python syntax error in '{dotted.value}': {functions.msg}",
                   dotted.span)
        return None
    return functions
