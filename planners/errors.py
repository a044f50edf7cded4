"""Errors raised by planners on bad input.

Every error names the offending value and the limit it breaks (README.md, "Conventions").
They subclass ValueError so callers can catch them as bad input; the CLI turns them into exit
code 2 with one line on stderr.
"""


class PlanningError(ValueError):
    """A planner was given input it cannot plan for (bad key points, limits, NaN...)."""


class LimitError(PlanningError):
    """A requested or planned value lies outside a joint, strut or workspace limit."""
