"""Plots: report.png of a run and plan.png of a planned motion (matplotlib, Agg)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def _to_display(values: np.ndarray, kinds: list[str]):
    """SI to display units per column: m -> mm for slides, rad -> deg for hinges."""
    scale = np.array([1e3 if k == "slide" else np.rad2deg(1.0) for k in kinds])
    return values * scale


def plan_plot(sample, labels, kinds, path, title: str, key_times=None, key_points=None) -> None:
    """Positions, velocities and accelerations of a planned motion, one column per joint."""
    units = ["mm" if k == "slide" else "deg" for k in kinds]
    fig, axes = plt.subplots(3, 1, figsize=(10, 9), sharex=True)
    for ax, data, what in zip(
        axes,
        (sample.position, sample.velocity, sample.acceleration),
        ("position", "velocity", "acceleration"),
    ):
        shown = _to_display(data, kinds)
        for j, label in enumerate(labels):
            ax.plot(sample.t, shown[:, j], label=f"{label} [{units[j]}]")
        ax.set_ylabel({"position": "unit", "velocity": "unit/s", "acceleration": "unit/s²"}[what])
        ax.set_title(what, fontsize=10, loc="left")
        ax.grid(alpha=0.3)
    if key_times is not None:
        shown = _to_display(np.asarray(key_points), kinds)
        for j in range(shown.shape[1]):
            axes[0].plot(key_times, shown[:, j], "ko", ms=3)
    axes[0].legend(fontsize=8, ncol=3)
    axes[-1].set_xlabel("t [s]")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def checks_text(checks) -> str:
    """One line per check; one that could not be evaluated reads "not evaluated", not nan."""
    return "\n".join(
        f"{'PASS' if c.passed else 'FAIL'} {c.name}: "
        f"{f'{c.value:.4g} {c.unit}' if c.evaluated else 'not evaluated'} ({c.comparison} {c.limit:g})"
        for c in checks
    )


def loader_report(ts: dict, t: np.ndarray, checks, path) -> None:
    """report.png of a loader run: joints, tracking error, drive load, clearance."""
    names = [str(n) for n in ts["joint_names"]]
    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5))
    ax = axes[0, 0]
    for j in range(1, len(names)):
        line, = ax.plot(t, np.rad2deg(ts["q_actual"][:, j]), label=names[j])
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
    _finish(fig, axes, ax, checks, path, top=True)


def _finish(fig, axes, text_ax, checks, path, top: bool) -> None:
    """Checks in a box on ``text_ax``, grids, layout, save at 90 dpi, close."""
    text_ax.text(0.02, 0.97 if top else 0.03, checks_text(checks), transform=text_ax.transAxes,
                 va="top" if top else "bottom", fontsize=7, family="monospace",
                 bbox=dict(facecolor="white", alpha=0.8))
    for a in axes.flat:
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def hexapod_report(ts: dict, t: np.ndarray, checks, path) -> None:
    """report.png of a hexapod run: struts, following error, drive forces, pose error."""
    names = [str(n) for n in ts["strut_names"]]
    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5))
    ax = axes[0, 0]
    for j, name in enumerate(names):
        line, = ax.plot(t, 1e3 * ts["strut_position_actual"][:, j], label=name)
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
    _finish(fig, axes, ax, checks, path, top=False)


def antenna_report(ts: dict, t: np.ndarray, checks, path, pointing_limit_deg: float) -> None:
    """report.png of an antenna run: ship motion, joints, pointing errors, drive loads."""
    names = [str(n) for n in ts["joint_names"]]
    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5))
    ax = axes[0, 0]
    for key in ("ship_heading", "ship_pitch", "ship_roll"):
        ax.plot(t, np.rad2deg(ts[key]), label=key.removeprefix("ship_"))
    ax.set(title="ship motion (deck joints)", xlabel="t [s]", ylabel="deg")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    for j, name in enumerate(names):
        line, = ax.plot(t, np.rad2deg(ts["theta_actual"][:, j]), label=name)
        ax.plot(t, np.rad2deg(ts["theta_planned"][:, j]), "--", color=line.get_color(), lw=0.8)
    ax.set(title="joint angles (solid: simulated, dashed: planned for the true motion)",
           xlabel="t [s]", ylabel="deg")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    ratio_t = np.abs(ts["torque_demanded"]) / ts["torque_limit"]
    ratio_v = np.abs(ts["theta_rate"]) / ts["rate_limit"]
    for j, name in enumerate(names):
        line, = ax.plot(t, ratio_t[:, j], lw=0.8, label=f"{name} torque")
        ax.plot(t, ratio_v[:, j], ":", color=line.get_color(), lw=0.8)
    ax.axhline(1.0, color="r", lw=0.8)
    ax.set(title="|torque| / limit (solid), |rate| / rated speed (dotted)", xlabel="t [s]",
           ylabel="ratio")
    ax.legend(fontsize=8)
    ax = axes[1, 1]
    ax.plot(t, ts["pointing_error_deg"], lw=0.8, label="pointing")
    ax.plot(t, np.abs(ts["polarization_error_deg"]), lw=0.8, label="|polarization|")
    ax.axhline(pointing_limit_deg, color="r", lw=0.8)
    ax.set(title="pointing and polarization error", xlabel="t [s]", ylabel="deg")
    ax.legend(fontsize=8, loc="upper right")
    _finish(fig, axes, ax, checks, path, top=True)


def antenna_methods_plot(paths: dict, path) -> None:
    """The paper's Figures 2-8: joint angles and rates of the pseudo-inverse integration and
    of CRR, and the attitude error ||f(Theta) - N||_F of every method."""
    pinv, crr = paths["pinv"], paths["crr"]
    names = ["azimuth", "elevation", "cross_elevation", "polarization"]
    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5))
    ax = axes[0, 0]
    for j, name in enumerate(names):
        line, = ax.plot(crr.t, np.rad2deg(crr.theta[:, j]), label=name)
        ax.plot(pinv.t, np.rad2deg(pinv.theta[:, j]), "--", color=line.get_color(), lw=0.8)
    ax.set(title="joint angles: CRR (solid, Fig. 5), pinv integration (dashed, Fig. 3)",
           xlabel="t [s]", ylabel="deg")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    rates = np.rad2deg(crr.rates())
    for j, name in enumerate(names):
        ax.plot(crr.t[1:], rates[:, j], label=name)
    ax.set(title="CRR joint rates from position differences (Fig. 8)", xlabel="t [s]", ylabel="deg/s")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    labels = {"pinv": "pinv integration (Fig. 4)", "crr": "CRR, eq. (6) (Fig. 7)",
              "crr_log": "CRR, exact angular velocity", "crr_full": "CRR + full correction"}
    for key, p in paths.items():
        ax.semilogy(p.t[1:], np.maximum(p.error_fro[1:], 1e-17), lw=0.8, label=labels.get(key, key))
    ax.axhline(1e-6, color="r", lw=0.8)
    ax.set(title="attitude error ||f(Theta) - N(t)||_F", xlabel="t [s]", ylabel="Frobenius norm")
    ax.legend(fontsize=8)
    ax = axes[1, 1]
    for key in ("crr", "crr_log", "crr_full"):
        p = paths[key]
        ax.plot(p.t[1:], p.iterations[1:], lw=0.8, label=labels[key])
    ax.set(title="Newton iterations per update", xlabel="t [s]", ylabel="iterations")
    ax.legend(fontsize=8)
    for a in axes.flat:
        a.grid(alpha=0.3)
    fig.suptitle("ship antenna, the paper's section 5: eq. (15)-(16), dT = 0.01 s, W = [10, 5, 2, 1]")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


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
        ax.fill_between(t, 0, 1, where=observing, transform=ax.get_xaxis_transform(),
                        color="0.93", lw=0)
    ax = axes[0, 0]
    ax.plot(t, ts["feed_error_mm"], lw=0.7, label="feed |actual - planned|")
    ax.plot(t, 1e3 * np.linalg.norm(ts["cabin_pos_actual"] - ts["cabin_pos_planned"], axis=1), lw=0.7,
            label="cabin origin")
    ax.set(title="position errors (grey: observing)", xlabel="t [s]", ylabel="mm")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    for j, name in enumerate(ts["cable_names"]):
        line, = ax.plot(t, ts["cable_tension"][:, j] / 1e3, lw=0.7, label=str(name))
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
    _finish(fig, axes, axes[0, 1], checks, path, top=False)  # below the tensions, above 0
