"""report.png of a loader run (matplotlib, Agg: planbench.report)."""

from __future__ import annotations

import numpy as np

from planbench.report import finish, plt


def loader_report(ts: dict, t: np.ndarray, checks, path) -> None:
    """report.png of a loader run: joints, tracking error, drive load, clearance."""
    names = [str(n) for n in ts["joint_names"]]
    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5))
    ax = axes[0, 0]
    for j in range(1, len(names)):
        (line,) = ax.plot(t, np.rad2deg(ts["q_actual"][:, j]), label=names[j])
        ax.plot(t, np.rad2deg(ts["q_planned"][:, j]), "--", color=line.get_color(), lw=0.8)
    ax.plot(ts["key_times"], np.rad2deg(ts["key_points"][:, 1:]), "ko", ms=3)
    ax.set(title="joint angles (solid: simulated, dashed: planned)", xlabel="t [s]", ylabel="deg")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    err = np.rad2deg(ts["q_actual"][:, 1:] - ts["q_planned"][:, 1:])
    for j in range(1, len(names)):
        ax.plot(t, err[:, j - 1], label=names[j])
    ax.set(title="tracking error", xlabel="t [s]", ylabel="deg")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    ratio = ts["drive_force_demanded"] / ts["drive_force_limit"]
    for j, name in enumerate(names):
        ax.plot(t, ratio[:, j], label=name)
    ax.axhline(1.0, color="r", lw=0.8)
    ax.axhline(-1.0, color="r", lw=0.8)
    ax.set(title="demanded drive force / limit", xlabel="t [s]", ylabel="ratio")
    ax.legend(fontsize=8)
    ax = axes[1, 1]
    ax.plot(t, 1e3 * ts["clearance"])
    ax.axhline(0.0, color="r", lw=0.8)
    ax.set(title="clearance to breechblock, seat ring, floor", xlabel="t [s]", ylabel="mm")
    finish(fig, axes, ax, checks, path, top=True)
