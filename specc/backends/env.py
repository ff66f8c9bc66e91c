"""The one jinja2 Environment every back end renders with (strict, deterministic, and safe).

Nothing taken from a spec reaches generated code unescaped. Every `{{ ... }}` of a template goes
through `finalize`, which writes a number as its literal and `Code` (source a back end built from
checked pieces) as it is, and refuses any other string: a template marks each one with the
filter for where it lands,

- `py`: a Python literal (a string in double quotes, escaped as JSON escapes it, which Python
  reads the same; numbers, booleans, None, tuples as `repr` writes them);
- `ident` / `idents`: an identifier (or a comma-separated list of them), checked;
- `doc`: text inside a triple-quoted docstring (backslashes and quotes escaped, control
  characters written as escapes);
- `comment`: text on a comment line (the same, and no line break),

so that a spec string holding quotes, backslashes, `\\N{...}`, triple quotes, line breaks, NUL or
ESC bytes cannot end a literal, a docstring or a comment and run as code when the package is
imported.
"""

from __future__ import annotations

import functools
import json
import keyword
import math
import re
from collections.abc import Iterable
from typing import Any

import jinja2

from specc.resources import templates_dir

# Control characters but the line break (a docstring may hold one): written as escapes.
_CONTROL = re.compile(r"[\x00-\x09\x0b-\x1f\x7f\u2028\u2029]")


class Code(str):
    """Python source a back end built from checked pieces (identifiers, `py` literals, records
    written by `specc.backends.records.literal`): a template writes it as it is."""

    __slots__ = ()


class UnescapedValue(jinja2.TemplateError):
    """A template wrote a string without saying how it lands in the generated code."""


def py(value: Any) -> Code:
    """`value` as a Python literal."""
    if isinstance(value, str):
        return Code(json.dumps(str(value), ensure_ascii=False))
    if isinstance(value, float) and not math.isfinite(value):
        raise UnescapedValue(f"{value!r} has no Python literal: the spec's checks should have refused it")
    if isinstance(value, list):
        return Code(f"[{', '.join(py(v) for v in value)}]")
    if isinstance(value, tuple):
        items = [py(v) for v in value]
        return Code(f"({items[0]},)" if len(items) == 1 else f"({', '.join(items)})")
    if isinstance(value, dict):
        return Code(f"{{{', '.join(f'{py(k)}: {py(v)}' for k, v in value.items())}}}")
    if value is None or isinstance(value, bool | int | float):
        return Code(repr(value))
    raise UnescapedValue(f"no Python literal for a {type(value).__name__}")


def ident(value: Any) -> Code:
    """An identifier of the generated code, checked (the spec's checks refuse any other)."""
    text = str(value)
    if not text.isidentifier() or keyword.iskeyword(text):
        raise UnescapedValue(f"{text!r} is not a Python identifier: the spec's checks should have refused it")
    return Code(text)


def idents(values: Iterable[Any], separator: str = ", ") -> Code:
    return Code(separator.join(ident(v) for v in values))


def doc(value: Any) -> Code:
    """Text that stays inside a triple-quoted (non-raw) docstring."""
    # A quote next to another or at the end could close the docstring: those are escaped.
    text = re.sub(r'"(?="|$)', r'\\"', str(value).replace("\\", "\\\\"))
    return Code(_CONTROL.sub(lambda m: f"\\x{ord(m.group()):02x}" if ord(m.group()) < 0x100
                             else f"\\u{ord(m.group()):04x}", text))


def comment(value: Any) -> Code:
    """Text that stays on one comment line."""
    return Code(doc(value).replace("\r", "\\r").replace("\n", "\\n"))


def finalize(value: Any) -> Any:
    if isinstance(value, Code):
        return value
    if isinstance(value, bool | int | float) or value is None:
        return py(value)
    if isinstance(value, str):
        raise UnescapedValue(f"the template writes {value[:60]!r} without saying how it lands in the code: "
                             "mark it with py, ident, doc or comment (or build it as Code)")
    raise UnescapedValue(f"the template writes a {type(value).__name__}: only Code, numbers and escaped text")


@functools.lru_cache(maxsize=1)
def environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(templates_dir())),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        autoescape=False,
        finalize=finalize,
    )
    env.filters.update(py=py, ident=ident, idents=idents, doc=doc, comment=comment)
    return env


def render(template: str, **context: object) -> str:
    return environment().get_template(template).render(**context)
