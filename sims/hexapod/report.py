"""report.png of a hexapod run (matplotlib, Agg: planbench.report)."""

from __future__ import annotations

import numpy as np

from planbench.report import finish, plt


def hexapod_report(ts: dict, t: np.ndarray, checks, path) -> None:
    """report.png of a hexapod run: struts, following error, drive forces, pose error."""
    names = [str(n) for n in ts["strut_names"]]
    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5))
    ax = axes[0, 0]
    for j, name in enumerate(names):
        (line,) = ax.plot(t, 1e3 * ts["strut_position_actual"][:, j], label=name)
        ax.plot(t, 1e3 * ts["strut_position_planned"][:, j], "--", color=line.get_color(), lw=0.8)
    ax.set(title="strut length change (solid: encoder, dashed: generator)", xlabel="t [s]", ylabel="mm")
    ax.legend(fontsize=8, ncol=2)
    ax = axes[0, 1]
    err = 1e6 * (ts["strut_position_actual"] - ts["strut_position_planned"])
    for j, name in enumerate(names):
        ax.plot(t, err[:, j], label=name)
    ax.set(title="following error (encoder - reference)", xlabel="t [s]", ylabel="um")
    ax.legend(fontsize=8, ncol=2)
    ax = axes[1, 0]
    for j, name in enumerate(names):
        ax.plot(t, 1e-3 * ts["drive_force_demanded"][:, j], label=name)
    limit = 1e-3 * float(np.min(ts["drive_force_limit"]))
    ax.axhline(limit, color="r", lw=0.8)
    ax.axhline(-limit, color="r", lw=0.8)
    ax.set(title="drive force (push +), limit in red", xlabel="t [s]", ylabel="kN")
    ax.legend(fontsize=8, ncol=2)
    ax = axes[1, 1]
    ax.semilogy(t, np.maximum(ts["pivot_error_um"], 1e-4), label="pose error to target (largest pivot)")
    ax.axhline(1.0, color="r", lw=0.8)
    if "wind_force" in ts:
        twin = ax.twinx()
        twin.plot(t, np.linalg.norm(ts["wind_force"], axis=1), color="0.6", lw=0.6)
        twin.set_ylabel("wind drag [N]", color="0.4")
    ax.set(title="distance to the target pose", xlabel="t [s]", ylabel="um")
    finish(fig, axes, ax, checks, path, top=False)
