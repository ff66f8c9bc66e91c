"""The specc model: frozen AST dataclasses with spans, and a visitor."""

from specc.model.nodes import *  # noqa: F403
from specc.model.span import NO_SPAN, Span
from specc.model.visitor import Visitor, children, walk

__all__ = ["NO_SPAN", "Span", "Visitor", "children", "walk"]
