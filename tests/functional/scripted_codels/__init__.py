"""Codels that play the script of their request: `script` is a comma-separated list of what
the successive codel calls return. `raise` raises, `exit` calls sys.exit(3), `none` returns None, `send:X` sends
beta.Child with script X (X's own steps separated by `;`) and continues with `exec`.
`to:module.request:X:R` sends that request (script X, steps separated by `;`; `-` for a request
without input) and returns R; `write:P` writes poster P by hand and continues with `exec`;
`copy` copies the SDI's value into `copied` and continues with `exec`; `mode:M` sets the SDI's enum
field `mode` to the text M and continues with `exec`; `badtrace` writes a number into the string
output `trace` and ends."""

def play(state, sdi, request):
    script = [s for s in request.script.split(",") if s]
    request.trace = (request.trace + "," if request.trace else "") + state
    if request.step >= len(script):
        return "ether"
    outcome = script[request.step]
    request.step += 1
    if outcome == "raise":
        raise ValueError("scripted failure")
    if outcome == "exit":
        import sys

        sys.exit(3)
    if outcome == "none":
        return None
    if outcome.startswith("send:"):
        sdi.send_request("beta.Child", script=outcome[5:].replace(";", ","))
        return "exec"
    if outcome.startswith("to:"):
        _, target, child_script, result = outcome.split(":")
        if child_script == "-":
            sdi.send_request(target)
        else:
            sdi.send_request(target, script=child_script.replace(";", ","))
        return result
    if outcome.startswith("write:"):
        sdi.write_poster(outcome[6:])
        return "exec"
    if outcome == "copy":
        sdi.copied = sdi.value
        return "exec"
    if outcome.startswith("mode:"):
        sdi.mode = outcome[5:]
        return "exec"
    if outcome == "badtrace":  # an output of the wrong type, and the activity ends
        request.trace = 7
        return "ether"
    return outcome
