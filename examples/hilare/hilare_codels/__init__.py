"""User codels of the Hilare 2 example (seed 000 ch. 5).

One Python module per GenoM module (``codels: "hilare_codels.<module>"`` in each spec), plus
``executive.py`` (input/output functions of the executive's services) and ``prs.py`` (primitive
actions of the task level). PLAN, PILO and EXPLOR run the algorithms of §5.2.2, §5.2.1 and §5.2.5
(pure functions, tested in tests/test_hilare_algorithms.py); the others are minimal placeholders.

Interface these codels assume from the runtime (kept deliberately small):

* ``sdi`` - the module's internal data (GenoM SDI/f), one attribute per ``internal_data`` field;
  struct values have one attribute per struct field, arrays are Python lists.
* ``request`` - the activity's request, one attribute per ``input`` and ``output`` field.
* ``sdi.read_poster("module.Poster")`` - the content of another module's poster (``None`` if it
  does not exist); a poster with a single ``data`` field yields that field's value.
* ``sdi.send_request("module.request", **inputs)`` - the client side of a module-to-module request
  (PILO -> AVOID -> US, LOCO of Fig 5.3).
* A codel returns the name of the next state: ``"exec"`` (run the exec codel again next period),
  ``"end"`` (go to the end codel, or finish a control request), ``"ether"`` (activity over), or
  the name of one of the request's ``fail:`` messages (upper case) to end with that error.
  Validate codels (control requests) return ``"end"`` to accept. Init and permanent codels of an
  exec task take only ``sdi`` and return ``"exec"``.
"""
