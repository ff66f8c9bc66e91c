"""Semantic analysis, first: the program's names, resolved once into tables that the check passes,
the analyses and the back ends read (mypy's way: its semantic analyzer binds every name to a
symbol-table entry before any later pass runs).

The tables hold the blocks by kind and name, each module's requests and posters, the module of
each request, and each executive's services. A block, request or poster defined twice is listed
under its first definition: `names` and `modules` report the second one. The resolution of a
cross-layer reference (`module.request`, `module.Poster[.field]`, a service's request) is done
here, never again by hand in a pass, an analysis or a back end; the passes report what does not
resolve, with their own codes.
"""

from __future__ import annotations

import weakref
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol, TypeVar

from specc.model import nodes as m

# The kinds of top-level blocks, each a namespace of its own, with the word messages use.
KIND_WORDS: dict[type, str] = {
    m.Module: "module", m.Executive: "executive", m.RuleBase: "rules", m.Procedures: "procedures",
    m.Domain: "domain", m.Problem: "problem", m.Fragment: "fragment", m.FtPlan: "ftplan",
    m.System: "system",
}


class _HasName(Protocol):
    @property
    def name(self) -> str: ...


Named = TypeVar("Named", bound=_HasName)


@dataclass(frozen=True)
class Symbols:
    """The names a program defines, by kind, for the checks to look up."""

    blocks: Mapping[type, Mapping[str, Any]]  # kind -> name -> the block (its first definition)
    requests: Mapping[str, Mapping[str, m.Request]]  # module -> request name -> request
    posters: Mapping[str, Mapping[str, m.Poster]]  # module -> poster name -> poster
    _module_of: Mapping[int, m.Module]  # id(request) -> the module declaring it
    _own_requests: Mapping[int, Mapping[str, m.Request]]  # id(module) -> its requests (a duplicate module too)
    _own_services: Mapping[int, Mapping[str, m.Service]]  # id(executive) -> its services
    offered: Mapping[str, m.Service]  # every executive's services by name (the first of a name)

    def request(self, ref: m.Ref) -> m.Request | None:
        """`module.request` -> the request, None when it names none (or is not written so)."""
        if len(ref.parts) != 2:
            return None
        return self.requests.get(ref.parts[0], {}).get(ref.parts[1])

    def requests_of(self, module: m.Module) -> Mapping[str, m.Request]:
        """The module's own requests by name (of this very block, when two modules share a name)."""
        return self._own_requests.get(id(module), {})

    def services_of(self, executive: m.Executive) -> Mapping[str, m.Service]:
        """The executive's own services by name (of this very block)."""
        return self._own_services.get(id(executive), {})

    def module_of(self, request: m.Request) -> m.Module | None:
        return self._module_of.get(id(request))

    def service_request(self, service: m.Service) -> m.Request | None:
        """The module request an executive service runs."""
        return self.request(service.request) if service.request is not None else None

    def sent(self, request: m.Request) -> list[tuple[str, m.Request]]:
        """(module, request) for each request `request`'s codels send (`sends:`), and those those
        send in turn, each once."""
        found: dict[tuple[str, str], m.Request] = {}
        pending = [request]
        while pending:
            for ref in pending.pop().sends:
                target = self.request(ref)
                if target is not None and tuple(ref.parts) not in found:
                    found[(ref.parts[0], ref.parts[1])] = target
                    pending.append(target)
        return [(key[0], target) for key, target in found.items()]


def first_by_name(items: Iterable[Named]) -> dict[str, Named]:
    """Items by name, the first of each name (the checks report a name defined twice)."""
    found: dict[str, Named] = {}
    for item in items:
        found.setdefault(item.name, item)
    return found


def build(program: m.Program) -> Symbols:
    blocks: dict[type, dict[str, Any]] = {
        kind: first_by_name(item for item in program.items if type(item) is kind) for kind in KIND_WORDS}
    modules = [item for item in program.items if isinstance(item, m.Module)]
    executives = [item for item in program.items if isinstance(item, m.Executive)]
    own_requests = {id(module): first_by_name(module.requests) for module in modules}
    module_of = {id(request): module for module in modules for request in module.requests}
    requests = {name: own_requests[id(module)] for name, module in blocks[m.Module].items()}
    posters = {module.name: first_by_name(module.posters) for module in blocks[m.Module].values()}
    own_services = {id(executive): first_by_name(executive.services) for executive in executives}
    offered = first_by_name(service for executive in executives for service in executive.services)
    return Symbols(blocks, requests, posters, module_of, own_requests, own_services, offered)


# The tables of the programs in use, by identity: a program is a frozen tree, built once per load,
# and every pass, analysis and back end of that load reads the same tables. Dropped with it.
_TABLES: dict[int, tuple[weakref.ref[m.Program], Symbols]] = {}


def symbols_of(program: m.Program) -> Symbols:
    """The program's symbol tables, built on first use."""
    known = _TABLES.get(id(program))
    if known is not None and known[0]() is program:
        return known[1]
    tables = build(program)
    key = id(program)
    _TABLES[key] = (weakref.ref(program, lambda _: _TABLES.pop(key, None)), tables)
    return tables
