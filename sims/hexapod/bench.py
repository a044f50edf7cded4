"""``planbench bench``'s planner rows for the hexapod: batch planning throughput."""

from __future__ import annotations

import numpy as np

from planbench.bench import best_time

PLANNING_MOVES = 10_000


def planning_throughput(n_moves: int = PLANNING_MOVES, seed: int = 0) -> list[dict]:
    """Moves per second of the hexapod generator planning ``n_moves`` random moves at once.

    Start and target poses are uniform inside the pose limits and the stroke; the time
    includes the inverse kinematics, the limit checks and the tick realization (best of
    REPEATS), for both modes and both long-move solvers (closed form, the paper's iteration).
    """
    from planbench.planners import hexapod

    rng = np.random.default_rng(seed)
    start, target = hexapod.random_poses(n_moves, rng), hexapod.random_poses(n_moves, rng)
    rows = []
    for synchronous in (True, False):
        for method in ("closed", "iteration"):
            best, moves = best_time(
                lambda synchronous=synchronous, method=method: hexapod.plan_moves(
                    start, target, synchronous=synchronous, method=method
                )
            )
            rows.append(
                {
                    "mode": "sync" if synchronous else "async",
                    "method": method,
                    "moves": len(moves),
                    "wall_s": best,
                    "moves_per_s": len(moves) / best,
                }
            )
    return rows


def format_planning(rows: list[dict]) -> str:
    lines = [f"{'hexapod batch planning':<24} {'moves':>7} {'wall s':>8} {'moves/s':>10}"]
    for r in rows:
        lines.append(
            f"{r['mode'] + ', ' + r['method']:<24} {r['moves']:>7d} {r['wall_s']:>8.4f} {r['moves_per_s']:>10.0f}"
        )
    return "\n".join(lines)


def planner_benchmark() -> str:
    """The rows ``planbench bench`` prints after the scenario table."""
    return format_planning(planning_throughput())
