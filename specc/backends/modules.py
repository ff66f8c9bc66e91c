"""Back end `modules`: one Python module per GenoM module (seed 000 §2.4), in `<robot>/modules/`.

Each holds the typed records (structs, enums, the SDI, request inputs and outputs, posters),
the module's static description for `specc.runtime.functional`, a typed client, and `create()`
binding it to the user's codels. Names are computed here; the templates only lay them out.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from functools import cached_property

from specc.backends.env import Code, ident, py, render
from specc.backends.manifest import Output, describe_sources, header
from specc.model import nodes as m
from specc.pysource import camel

BACKEND = "modules"

# spec type -> (annotation, default, checker kind)
PRIMITIVES = {
    "double": ("float", "0.0", '"float"'), "float": ("float", "0.0", '"float"'),
    "int": ("int", "0", '"int"'), "long": ("int", "0", '"int"'),
    "bool": ("bool", "False", '"bool"'),
    "string": ("str", '""', '"str"'), "char": ("str", '""', '"str"'),
}


# How the generated modules import dataclasses.field: a dunder name no spec field can take
# (`reserved-name`), so that no field of a record hides it in the class body.
FIELD = "__field__"


@dataclass(frozen=True)
class FieldView:
    """One field of a generated record, with what its dataclass line and type check need."""

    name: str
    annotation: str
    default: str  # a dataclass default: `0.0` or `__field__(default_factory=lambda: ...)`
    kind: str  # the runtime checker's kind: "float", ..., or a record class
    size: str  # "None" or the array length

    @property
    def declaration(self) -> Code:
        return Code(f"{ident(self.name)}: {self.annotation} = {self.default}")

    @property
    def check(self) -> Code:
        return Code(f'({py(self.name)}, {self.kind}, {self.size})')


@dataclass(frozen=True)
class RecordView:
    name: str
    fields: tuple[FieldView, ...]
    base: str = ""
    doc: str = ""
    slots: bool = False  # a typo'd field assigned by a codel raises instead of adding a field

    @property
    def checks(self) -> Code:
        inner = ", ".join(f.check for f in self.fields)
        return Code(f"({inner},)" if self.fields else "()")


class ModuleView:
    def __init__(self, module: m.Module, source: str):
        self.module = module
        self.source = source
        self.enums = {e.name: e for e in module.enums}
        self.structs = {s.name: s for s in module.structs}

    @property
    def header(self) -> str:
        return header(self.source)

    @property
    def name(self) -> str:
        return self.module.name

    @property
    def number(self) -> int:
        return int(self.module.number.value) if self.module.number is not None else 0

    @property
    def codel_module(self) -> str:
        return self.module.codel_module.value if self.module.codel_module is not None else ""

    @property
    def prefix(self) -> str:
        return camel(self.module.name)

    def field(self, name: str, type_ref: m.TypeRef) -> FieldView:
        annotation, value, kind = self.scalar(type_ref.name)
        literal = type_ref.name in PRIMITIVES
        if type_ref.size is None:
            # A default naming a type (or `field`) would be looked up in the class body, where an
            # earlier field of that name hides it: a lambda looks names up in the module.
            default = value if literal else f"{FIELD}(default_factory=lambda: {value})"
            return FieldView(name, annotation, default, kind, "None")
        elements = f"[{value}] * {type_ref.size}" if literal else f"[{value} for _ in range({type_ref.size})]"
        return FieldView(name, f"list[{annotation}]", f"{FIELD}(default_factory=lambda: {elements})", kind,
                         str(type_ref.size))

    def scalar(self, type_name: str) -> tuple[str, str, str]:
        """The type's annotation, an expression giving its default value, its check kind."""
        if type_name in PRIMITIVES:
            return PRIMITIVES[type_name]
        if type_name in self.enums:
            first = self.enums[type_name].values[0]
            return type_name, f"{type_name}.{first}", type_name
        return type_name, f"{type_name}()", type_name

    @cached_property
    def sdi_types(self) -> dict[str, m.TypeRef]:
        return {f.name: f.type for f in self.module.internal_data}

    @property
    def enum_views(self) -> list[m.EnumDecl]:
        return list(self.module.enums)

    @property
    def struct_views(self) -> list[RecordView]:
        return [RecordView(s.name, tuple(self.field(f.name, f.type) for f in s.fields)) for s in self.ordered_structs()]

    def ordered_structs(self) -> list[m.StructDecl]:
        """Structs in dependency order, so each class exists before a field uses it."""
        done: list[m.StructDecl] = []
        seen: set[str] = set()

        def visit(struct: m.StructDecl) -> None:
            if struct.name in seen:
                return
            seen.add(struct.name)
            for f in struct.fields:
                if f.type.name in self.structs:
                    visit(self.structs[f.type.name])
            done.append(struct)

        for struct in self.module.structs:
            visit(struct)
        return done

    @property
    def sdi(self) -> RecordView:
        return RecordView(f"{self.prefix}Data", tuple(self.field(f.name, f.type) for f in self.module.internal_data),
                          base=Code("rt.InternalData"), doc=f"The internal data (SDI) of module {self.name}.",
                          slots=True)

    @property
    def requests(self) -> list[RequestView]:
        return [RequestView(self, r) for r in self.module.requests]

    @property
    def records(self) -> list[RecordView]:
        records = []
        for request in self.requests:
            records += request.records
        records += [poster.record for poster in self.posters]
        return records

    @property
    def tasks(self) -> list[Code]:
        specs = []
        for task in self.module.exec_tasks:
            codels = {c.state: c.function for c in task.codels}
            specs.append(Code(
                f'rt.ExecTaskSpec(name={py(task.name)}, period={seconds(task.period)}, delay={seconds(task.delay)}, '
                f'priority={int(task.priority.value) if task.priority else 0}, init={quoted(codels.get("init"))}, '
                f'permanent={quoted(codels.get("permanent"))})'))
        return specs

    @property
    def posters(self) -> list[PosterView]:
        return [PosterView(self, p) for p in self.module.posters]


class RequestView:
    def __init__(self, module: ModuleView, request: m.Request):
        self.module = module
        self.request = request

    @property
    def name(self) -> str:
        return self.request.name

    @property
    def kind(self) -> str:
        return self.request.kind or "exec"

    @property
    def input_class(self) -> str | None:
        return f"{camel(self.name)}Input" if self.request.inputs else None

    @property
    def output_class(self) -> str | None:
        return f"{camel(self.name)}Output" if self.request.outputs else None

    @property
    def records(self) -> list[RecordView]:
        found = []
        for cls, entries, what in ((self.input_class, self.request.inputs, "input"),
                                   (self.output_class, self.request.outputs, "output")):
            if cls is not None:
                found.append(RecordView(cls, tuple(self.module.field(t.name, t.type) for t in entries),
                                        doc=f"The {what} of request {self.name}."))
        return found

    @property
    def spec(self) -> Code:
        r = self.request
        codels = ", ".join(f'{py(c.state)}: {py(c.function)}' for c in r.codels)
        yields = ", ".join(f'{py(c.state)}: {tuple_literal(c.yields)}' for c in r.codels if c.yields)
        return Code(f'rt.RequestSpec(name={py(r.name)}, kind={py(self.kind)}, input_type={self.input_class}, '
                f'output_type={self.output_class}, validate={quoted(r.validate.text if r.validate else None)}, '
                f"codels={{{codels}}}, yields={{{yields}}}, fail={tuple_literal(f.text for f in r.fail)}, "
                f"incompatible={tuple_literal(i.text for i in r.incompatible_with)}, "
                f"task={quoted(r.task.text if r.task else None)}, sends={tuple_literal(s.text for s in r.sends)})")

    @property
    def parameters(self) -> Code:
        return Code("".join(f"{ident(t.name)}: {self.module.field(t.name, t.type).annotation}, "
                            for t in self.request.inputs))

    @property
    def arguments(self) -> Code:
        if self.input_class is None:
            return Code("None")
        return Code(f"{self.input_class}(" + ", ".join(f"{ident(t.name)}={ident(t.name)}" for t in self.request.inputs)
                    + ")")

    @property
    def doc(self) -> str:
        fail = ", ".join(f.text for f in self.request.fail) or "none"
        return f"Send {self.name} ({self.kind} request; fail messages: {fail}). Returns the request id."


class PosterView:
    def __init__(self, module: ModuleView, poster: m.Poster):
        self.module = module
        self.poster = poster

    @property
    def name(self) -> str:
        return self.poster.name

    @property
    def cls(self) -> str:
        return f"{camel(self.name)}Poster"

    @property
    def record(self) -> RecordView:
        types = self.module.sdi_types
        fields = tuple(self.module.field(d.parts[0], types[d.parts[0]]) for d in self.poster.data
                       if d.parts[0] in types)
        return RecordView(self.cls, fields, doc=f"The content of poster {self.module.name}.{self.name}.")

    @property
    def spec(self) -> Code:
        p = self.poster
        fields = tuple_literal(d.parts[0] for d in p.data)
        return Code(f'rt.PosterSpec(name={py(p.name)}, type={self.cls}, fields={fields}, '
                    f'update={py(p.update or "auto")}, activity={quoted(p.activity.text if p.activity else None)})')


def seconds(duration: m.Duration | None) -> str:
    return repr(duration.seconds) if duration is not None else "0.0"


def quoted(text: str | None) -> Code:
    return py(text)


def tuple_literal(items: Iterable[object]) -> Code:
    return py(tuple(str(item) for item in items))


def generate(program: m.Program, output: Output, robot: str = "") -> None:
    modules = sorted((item for item in program.items if isinstance(item, m.Module)), key=lambda x: x.name)
    for module in modules:
        view = ModuleView(module, module.span.file)
        output.add(BACKEND, f"modules/{module.name}.py", render("modules/module.py.j2", view=view))
    names = [module.name for module in modules]
    if not modules:
        return
    sources = sorted({module.span.file for module in modules})
    output.add(BACKEND, "modules/__init__.py", render(
        "modules/__init__.py.j2", names=names, header=header(describe_sources(sources))))
