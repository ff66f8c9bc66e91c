"""Human labels for the parser's terminals, so syntax errors never show raw token names."""

from __future__ import annotations

from collections.abc import Iterable

from lark import Token

LABELS = {
    "NAME": "a name", "HNAME": "a hyphenated name", "NUMBER": "a number", "INT": "an integer",
    "STRING": "a quoted string", "SEMICOLON": "';'", "COLON": "':'", "COMMA": "','",
    "LBRACE": "'{'", "RBRACE": "'}'", "LPAR": "'('", "RPAR": "')'", "LSQB": "'['", "RSQB": "']'",
    "DOT": "'.'", "EQUAL": "'='", "CMP_OP": "a comparison (== != < <= > >= =.)",
    "SIGN": "a sign", "IXVAR": "a variable like ?x",
    "LOGIC_VAR": "a logic variable like $x", "PROGRAM_VAR": "a program variable like @x",
    "GOAL_OP": "a goal operator (! ? ^ => ~> # %)", "SEXP_OP": "an operator",
    "PREV": "'@'", "ADD_OP": "'+' or '-'", "MUL_OP": "'*' or '/'", "$END": "the end of the file",
    "MORETHAN": "'>'", "LESSTHAN": "'<'", "VBAR": "'|'", "BANG": "'!'", "MINUS": "'-'",
}


def describe_terminal(name: str, literals: dict[str, str] | None = None) -> str:
    if name in LABELS:
        return LABELS[name]
    if literals and name in literals:
        return f"'{literals[name]}'"
    if name.startswith("__ANON") or not name.isupper():
        return name.lower()
    # Keywords lark names after their text (e.g. MODULE, LATEPREEMPTIVE): show the word itself.
    return f"'{name.lower()}'"


def describe_expected(expected: Iterable[str], literals: dict[str, str] | None = None) -> str:
    labels = sorted({describe_terminal(name, literals) for name in expected})
    if not labels:
        return "something else"
    if len(labels) > 8:
        return ", ".join(labels[:8]) + f" or one of {len(labels) - 8} more"
    if len(labels) == 1:
        return labels[0]
    return ", ".join(labels[:-1]) + " or " + labels[-1]


def describe_token(token: Token) -> str:
    if token.type == "$END":
        return "end of file"
    text = str(token)
    return f"'{text}'" if len(text) <= 40 else f"'{text[:37]}...'"
