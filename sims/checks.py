"""Checks: a measured value against a limit, as reported in summary.json."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass


@dataclass(frozen=True)
class Check:
    """One pass/fail check of a run.

    ``comparison`` says how ``value`` must relate to ``limit``: "<=", "<", ">=", ">" or "==".
    A NaN value always fails (a quantity that could not be measured has not been shown to
    hold).
    """

    name: str
    value: float
    limit: float
    unit: str
    comparison: str = "<="
    note: str = ""

    @property
    def passed(self) -> bool:
        v, lim = float(self.value), float(self.limit)
        if math.isnan(v):
            return False
        return {
            "<=": v <= lim,
            "<": v < lim,
            ">=": v >= lim,
            ">": v > lim,
            "==": v == lim,
        }[self.comparison]

    def to_json(self) -> dict:
        out = asdict(self)
        out["value"] = _json_float(self.value)
        out["limit"] = _json_float(self.limit)
        out["passed"] = self.passed
        if not self.note:
            out.pop("note")
        return out


def _json_float(x: float):
    x = float(x)
    return x if math.isfinite(x) else str(x)


def divergence_check(warnings: dict[str, int], diverged_at: float | None, message: str) -> Check:
    """The run ended without NaN state or MuJoCo warnings (count of warnings must be 0)."""
    count = sum(warnings.values())
    if diverged_at is not None and count == 0:
        count = 1  # NaN found by the runner itself
    return Check("simulation_warnings", count, 0, "count", "==", note=message)
