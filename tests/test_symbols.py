"""The semantic analysis (specc/check/symbols.py): every cross-layer name resolved once, into the
tables the check passes, the analyses and the back ends read."""

from __future__ import annotations

import gc
from pathlib import Path

from specc.check.symbols import symbols_of
from specc.model import nodes as m
from specc.pipeline import load

ROOT = Path(__file__).resolve().parents[1]


def program(folder: str) -> m.Program:
    loaded = load([ROOT / "examples" / folder])
    assert loaded.program is not None and not loaded.errors
    return loaded.program


def test_a_program_has_one_set_of_tables_every_reader_shares() -> None:
    tug = program("tug")
    assert symbols_of(tug) is symbols_of(tug)
    other = program("tug")  # an equal program loaded again is another program: its own tables
    assert symbols_of(other) is not symbols_of(tug)


def test_services_requests_and_what_they_send_resolve_through_the_tables() -> None:
    hilare = program("hilare")
    symbols = symbols_of(hilare)
    executive = symbols.blocks[m.Executive]["hilare"]
    for service in executive.services:
        request = symbols.service_request(service)
        assert request is not None and service.request is not None
        assert request.name == service.request.parts[1]
        module = symbols.module_of(request)
        assert module is not None and module.name == service.request.parts[0]
        assert symbols.requests_of(module)[request.name] is request
    pilo = symbols.request(m.Ref(parts=("pilo", "execPosterTraj")))
    assert pilo is not None
    sent = symbols.sent(pilo)
    assert sent and all(symbols.request(ref) is not None for ref in pilo.sends)
    assert {module for module, _ in sent} >= {ref.parts[0] for ref in pilo.sends}
    assert symbols.request(m.Ref(parts=("pilo", "noSuchRequest"))) is None
    assert symbols.request(m.Ref(parts=("pilo",))) is None
    assert set(symbols.offered) == {s.name for s in executive.services}


def test_a_name_defined_twice_resolves_to_its_first_definition(tmp_path: Path) -> None:
    spec = tmp_path / "twice.spec"
    spec.write_text('module arm {\n  request Grab { type: control; }\n  request Grab { type: exec; }\n}\n'
                    'module arm {\n  request Other { type: control; }\n}\n')
    loaded = load([spec])
    assert loaded.program is not None
    assert "duplicate-definition" in {d.code for d in loaded.errors}
    symbols = symbols_of(loaded.program)
    first, second = (i for i in loaded.program.items if isinstance(i, m.Module))
    assert symbols.blocks[m.Module]["arm"] is first
    assert symbols.request(m.Ref(parts=("arm", "Grab"))) is first.requests[0]
    assert list(symbols.requests_of(second)) == ["Other"]  # each block keeps its own members


def test_the_tables_go_with_their_program() -> None:
    from specc.check import symbols as s

    tug = program("tug")
    symbols_of(tug)
    key = id(tug)
    assert key in s._TABLES
    del tug
    gc.collect()
    assert key not in s._TABLES
