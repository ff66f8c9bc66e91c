"""The planner's heuristics, by name (seed 004 §3.1: planners of one model made diverse by their
heuristics, which its prototype left undone, §3.2.2.2): a module of its own, so that a
configuration names them without importing the search.

Resolver orders (`heuristic:` of an FTplan planner block).

STANDARD: the orderings that solve a threat tried by the room they leave, most first (a resource
conflict's: the task found first goes first). LEAST_ROOM: every ordering choice the other way
round, so that its search departs from STANDARD's wherever it has an order to choose. Both link
an open condition to a producer already in the plan before they insert a new task.
"""

from __future__ import annotations

STANDARD = "most-room-first"
LEAST_ROOM = "least-room-first"
HEURISTICS = (STANDARD, LEAST_ROOM)

# Flaw orders (`flaws:` of a planner block): which task's open conditions are solved first.
# NEWEST_TASK_FIRST: the newest task's (its arguments get bound early, depth first: the default).
# OLDEST_TASK_FIRST: the oldest task's still open, breadth first over the tasks. On the rover's
# missions it finds the same goals with more partial plans; on the mutants of its model it plans
# where the default runs out of budget (it proves a broken task's goals impossible sooner), and
# the other way round: two planners of one model with the two orders tolerate more faults than
# either (docs/ftplan.md).
NEWEST_TASK_FIRST = "newest-task-first"
OLDEST_TASK_FIRST = "oldest-task-first"
FLAW_ORDERS = (NEWEST_TASK_FIRST, OLDEST_TASK_FIRST)

