"""The generated records' source (`specc.backends.records.literal`): what it writes is the value
back when Python reads it, fits the line width, and lays a long run of plain values out in full
lines rather than one value per line."""

from __future__ import annotations

import ast

from specc.backends.records import WIDTH, literal


def test_a_long_tuple_of_plain_values_fills_its_lines_and_reads_back_equal() -> None:
    words = tuple(f"WORD_{k}" for k in range(40)) + (1, 2.5, None, True)
    text = str(literal(words, (), 4))
    lines = text.splitlines()
    assert lines[0] == "(" and lines[-1] == "    )"
    assert all(len(line) <= WIDTH for line in lines)
    assert 2 < len(lines) < len(words) // 4  # several values a line, not one each
    assert ast.literal_eval(text) == words


def test_a_tuple_that_fits_stays_on_one_line() -> None:
    assert str(literal(("OK", "ERROR"), (), 0)) == "('OK', 'ERROR')"
    assert str(literal(("ONE",), (), 0)) == "('ONE',)"
