"""Checks: a measured value against a limit, as reported in summary.json."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

#: How the note of a check that could not be evaluated begins.
NOT_EVALUATED = "not evaluated"


@dataclass(frozen=True)
class Check:
    """One pass/fail check of a run.

    ``comparison`` says how ``value`` must relate to ``limit``: "<=", "<", ">=", ">" or "==".

    A check that cannot be evaluated (the run ended before the quantity exists: a settling
    window never reached, say) has the value NaN and fails: a quantity that could not be
    measured has not been shown to hold. Its note says why, and begins with
    ``NOT_EVALUATED``; build it with ``Check.not_evaluated``. A NaN value given without a
    reason gets a note that says so. summary.json (``to_json``) writes its value as null,
    never NaN (which is not JSON).
    """

    name: str
    value: float
    limit: float
    unit: str
    comparison: str = "<="
    note: str = ""

    def __post_init__(self):
        if not self.evaluated and not self.note.startswith(NOT_EVALUATED):
            reason = self.note or "its value is NaN and the evaluation gave no reason"
            object.__setattr__(self, "note", f"{NOT_EVALUATED}: {reason}")

    @classmethod
    def not_evaluated(cls, name: str, limit: float, unit: str, comparison: str = "<=", reason: str = "") -> Check:
        """A failed check whose value could not be measured, with the reason why."""
        return cls(name, float("nan"), limit, unit, comparison, note=reason)

    @property
    def evaluated(self) -> bool:
        """False when the value could not be measured (NaN)."""
        return not math.isnan(float(self.value))

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
        """The check as summary.json holds it: a value that could not be evaluated is null
        (its note says why), an infinite one the string "inf" or "-inf"; never NaN."""
        out = asdict(self)
        out["value"] = _json_float(self.value) if self.evaluated else None
        out["limit"] = _json_float(self.limit)
        out["passed"] = self.passed
        if not self.note:
            out.pop("note")
        return out


def _json_float(x: float):
    x = float(x)
    if math.isnan(x):
        return None
    return x if math.isfinite(x) else str(x)


def divergence_check(warnings: dict[str, int], diverged_at: float | None, message: str) -> Check:
    """The run ended without NaN state or MuJoCo warnings (count of warnings must be 0)."""
    count = sum(warnings.values())
    if diverged_at is not None and count == 0:
        count = 1  # NaN found by the runner itself
    return Check("simulation_warnings", count, 0, "count", "==", note=message)


def controller_check(error: tuple[float, str] | None) -> Check:
    """The controller ran every tick without raising and wrote only finite commands (count of
    faults must be 0). ``error``: (time in s, message) of the fault that ended the run."""
    if error is None:
        return Check("controller_errors", 0, 0, "count", "==")
    t, message = error
    return Check("controller_errors", 1, 0, "count", "==", note=f"the run ended at t = {t:.4f} s: {message}")
