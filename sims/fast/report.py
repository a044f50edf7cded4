"""report.png of a FAST run, and figures.png (the paper's Figures 16 and 17) (matplotlib, Agg: planbench.report)."""

from __future__ import annotations

import numpy as np

from planbench.report import finish, plt


def fast_plan_figure(plan, t: np.ndarray, path) -> None:
    """The paper's Figures 16-17 for a FAST plan: the feed's speed and acceleration (with each
    segment's limit), one cable's rate and acceleration, the tensions and tilts."""
    state = plan.state(t)
    sample = plan.sample(t)
    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5))
    for seg in plan.segments:
        for ax in axes.flat:
            ax.axvline(seg.t0, color="0.85", lw=0.6)
    ax = axes[0, 0]
    ax.plot(t, 1e3 * np.linalg.norm(state.feed_velocity, axis=1), label="|v|")
    for j, c in enumerate("xyz"):
        ax.plot(t, 1e3 * state.feed_velocity[:, j], lw=0.7, label=f"v{c}")
    ax.set(title="feed velocity (Fig. 16 left)", xlabel="t [s]", ylabel="mm/s")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    ax.plot(t, 1e3 * np.linalg.norm(state.feed_acceleration, axis=1), label="|a|")
    limit = np.array([plan.segments[k].accel_limit for k in state.segment])
    ax.plot(t, 1e3 * limit, "r", lw=0.8, label="segment limit")
    ax.set(title="feed acceleration (Fig. 16 right)", xlabel="t [s]", ylabel="mm/s²")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    ax.plot(t, 1e3 * sample.velocity[:, 7], label="cable1 rate [mm/s]")
    ax.plot(t, 1e3 * sample.acceleration[:, 7], label="cable1 acceleration [mm/s²]")
    ax.set(title="one cable (Fig. 17)", xlabel="t [s]")
    ax.legend(fontsize=8)
    ax = axes[1, 1]
    ax.plot(t, state.tension.min(axis=1) / 1e3, label="smallest tension [kN]")
    ax.plot(t, state.tension.max(axis=1) / 1e3, label="largest tension [kN]")
    ax.axhline(plan.limits.tension_min / 1e3, color="r", lw=0.8)
    twin = ax.twinx()
    twin.plot(t, np.rad2deg(state.zenith_angle), "k--", lw=0.8, label="zenith angle")
    twin.plot(t, np.rad2deg(state.cabin_tilt), "k:", lw=0.8, label="cabin tilt")
    twin.set_ylabel("deg")
    twin.legend(fontsize=8, loc="lower right")
    ax.set(title="static cable tensions, zenith angle, cabin tilt", xlabel="t [s]", ylabel="kN")
    ax.legend(fontsize=8, loc="upper left")
    for a in axes.flat:
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def fast_report(ts: dict, t: np.ndarray, checks, path, tension_min: float) -> None:
    """report.png of a FAST run: feed and cabin errors, cable tensions, Stewart legs, wind."""
    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5))
    observing = ts["observing"].astype(bool)
    for ax in axes.flat:
        ax.fill_between(t, 0, 1, where=observing, transform=ax.get_xaxis_transform(), color="0.93", lw=0)
    ax = axes[0, 0]
    ax.plot(t, ts["feed_error_mm"], lw=0.7, label="feed |actual - planned|")
    ax.plot(
        t, 1e3 * np.linalg.norm(ts["cabin_pos_actual"] - ts["cabin_pos_planned"], axis=1), lw=0.7, label="cabin origin"
    )
    ax.set(title="position errors (grey: observing)", xlabel="t [s]", ylabel="mm")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    for j, name in enumerate(ts["cable_names"]):
        (line,) = ax.plot(t, ts["cable_tension"][:, j] / 1e3, lw=0.7, label=str(name))
        ax.plot(t, ts["cable_tension_planned"][:, j] / 1e3, "--", color=line.get_color(), lw=0.6)
    ax.axhline(tension_min / 1e3, color="r", lw=0.8)
    ax.set_ylim(bottom=0.0)
    ax.set(title="cable tensions (dashed: planned statics), T_min in red", xlabel="t [s]", ylabel="kN")
    ax.legend(fontsize=8, ncol=3)
    ax = axes[1, 0]
    for j in range(ts["stewart_leg"].shape[1]):
        ax.plot(t, 1e3 * ts["stewart_leg"][:, j], lw=0.7, label=f"leg{j + 1}")
    ax.set(title="Stewart leg length changes", xlabel="t [s]", ylabel="mm")
    ax.legend(fontsize=8, ncol=3)
    ax = axes[1, 1]
    if "wind_speed" in ts:
        ax.plot(t, ts["wind_speed"], color="0.4", lw=0.6, label="wind speed [m/s]")
        twin = ax.twinx()
        twin.plot(t, np.linalg.norm(ts["wind_force"], axis=1) / 1e3, lw=0.6, label="drag on cabin and cables")
        twin.set_ylabel("kN")
        twin.legend(fontsize=8, loc="upper right")
        ax.legend(fontsize=8, loc="upper left")
    ax.set(title="wind", xlabel="t [s]", ylabel="m/s")
    finish(fig, axes, axes[0, 1], checks, path, top=False)  # below the tensions, above 0
