"""The planner's resolver orders, by name (`heuristic:` of an FTplan planner block; seed 004 §5.3:
planners of one model made diverse by their heuristics): a module of its own, so that a
configuration names them without importing the search.

STANDARD: the orderings that solve a threat tried by the room they leave, most first (a resource
conflict's: the task found first goes first). LEAST_ROOM: every ordering choice the other way
round, so that its search departs from STANDARD's wherever it has an order to choose. Both link
an open condition to a producer already in the plan before they insert a new task.
"""

from __future__ import annotations

STANDARD = "most-room-first"
LEAST_ROOM = "least-room-first"
HEURISTICS = (STANDARD, LEAST_ROOM)
