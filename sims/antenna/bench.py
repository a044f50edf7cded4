"""``planbench bench``'s planner rows for the antenna: joint-position updates per second."""

from __future__ import annotations

import numpy as np

from planbench.bench import best_time


def antenna_update_rate(duration: float = 60.0) -> list[dict]:
    """Joint-position updates per second of the antenna planner over the paper's conditions.

    The paper's section 5.1: 60 s of eq. (15)-(16) ship motion at dT = 0.01 s (6000 updates),
    for the pseudo-inverse integration (section 5.2), CRR (section 4.2) and CRR with the full
    correction; also CRR with the controller's safeguards (damping, rate-aware weights), and
    both CRR rows again by the online planner's one-pose path in plain floats
    (``crr_step_scalar``). Best of REPEATS. The paper's IMU delivers 20-50 attitudes per second.
    """
    from planbench.antenna.ship_motion import PaperShipMotion
    from planbench.planners import antenna

    t = np.arange(int(round(duration / antenna.PAPER_DT)) + 1) * antenna.PAPER_DT
    ship = PaperShipMotion().sample(t)
    az, el, pol = np.radians(antenna.PAPER_SATELLITE_DEG)
    attitudes = antenna.desired_attitude(ship.heading, ship.pitch, ship.roll, az, el, pol)
    theta0 = np.radians(antenna.PAPER_THETA0_DEG)
    limits = antenna.AntennaLimits(rate=np.radians([60.0, 60.0, 60.0, 90.0]))
    rows = []
    for label, method, lim, scalar in (
        ("pinv integration", "pinv", None, False),
        ("crr", "crr", None, False),
        ("crr + full correction", "crr-full", None, False),
        ("crr, safeguards on", "crr", limits, False),
        ("crr, floats", "crr", None, True),
        ("crr, safeguards on, floats", "crr", limits, True),
    ):
        best, path = best_time(
            lambda method=method, lim=lim, scalar=scalar: antenna.solve_joint_path(
                attitudes, antenna.PAPER_DT, theta0, method, limits=lim, scalar=scalar
            )
        )
        updates = t.size - 1
        rows.append(
            {
                "method": label,
                "updates": updates,
                "wall_s": best,
                "updates_per_s": updates / best,
                "error_fro_max": float(path.error_fro.max()),
            }
        )
    return rows


def format_antenna(rows: list[dict]) -> str:
    lines = [
        f"{'antenna planner (paper 5.1)':<28} {'updates':>7} {'wall s':>8} {'updates/s':>10} {'max ||f-N||_F':>14}"
    ]
    for r in rows:
        lines.append(
            f"{r['method']:<28} {r['updates']:>7d} {r['wall_s']:>8.4f} "
            f"{r['updates_per_s']:>10.0f} {r['error_fro_max']:>14.3e}"
        )
    return "\n".join(lines)


def planner_benchmark() -> str:
    """The rows ``planbench bench`` prints after the scenario table."""
    return format_antenna(antenna_update_rate())
