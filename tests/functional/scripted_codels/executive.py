"""Input and output functions of the executive in executive.spec."""

DEFAULT = "exec,exec,exec,exec,exec"


def next_script(ctx):
    """The script queued by the test for the next request (a short run by default)."""
    queued = ctx.vars.setdefault("next", [])
    return {"script": queued.pop(0) if queued else DEFAULT}


def value_of(ctx, outputs):
    return outputs.value
