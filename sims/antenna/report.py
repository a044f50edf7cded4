"""report.png of an antenna run, and methods.png (the paper's Figures 2-8) (matplotlib, Agg: planbench.report)."""

from __future__ import annotations

import numpy as np

from planbench.report import finish, plt


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
        (line,) = ax.plot(t, np.rad2deg(ts["theta_actual"][:, j]), label=name)
        ax.plot(t, np.rad2deg(ts["theta_planned"][:, j]), "--", color=line.get_color(), lw=0.8)
    ax.set(title="joint angles (solid: simulated, dashed: planned for the true motion)", xlabel="t [s]", ylabel="deg")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    ratio_t = np.abs(ts["torque_demanded"]) / ts["torque_limit"]
    ratio_v = np.abs(ts["theta_rate"]) / ts["rate_limit"]
    for j, name in enumerate(names):
        (line,) = ax.plot(t, ratio_t[:, j], lw=0.8, label=f"{name} torque")
        ax.plot(t, ratio_v[:, j], ":", color=line.get_color(), lw=0.8)
    ax.axhline(1.0, color="r", lw=0.8)
    ax.set(title="|torque| / limit (solid), |rate| / rated speed (dotted)", xlabel="t [s]", ylabel="ratio")
    ax.legend(fontsize=8)
    ax = axes[1, 1]
    ax.plot(t, ts["pointing_error_deg"], lw=0.8, label="pointing")
    ax.plot(t, np.abs(ts["polarization_error_deg"]), lw=0.8, label="|polarization|")
    ax.axhline(pointing_limit_deg, color="r", lw=0.8)
    ax.set(title="pointing and polarization error", xlabel="t [s]", ylabel="deg")
    ax.legend(fontsize=8, loc="upper right")
    finish(fig, axes, ax, checks, path, top=True)


def antenna_methods_plot(paths: dict, path) -> None:
    """The paper's Figures 2-8: joint angles and rates of the pseudo-inverse integration and
    of CRR, and the attitude error ||f(Theta) - N||_F of every method."""
    pinv, crr = paths["pinv"], paths["crr"]
    names = ["azimuth", "elevation", "cross_elevation", "polarization"]
    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5))
    ax = axes[0, 0]
    for j, name in enumerate(names):
        (line,) = ax.plot(crr.t, np.rad2deg(crr.theta[:, j]), label=name)
        ax.plot(pinv.t, np.rad2deg(pinv.theta[:, j]), "--", color=line.get_color(), lw=0.8)
    ax.set(title="joint angles: CRR (solid, Fig. 5), pinv integration (dashed, Fig. 3)", xlabel="t [s]", ylabel="deg")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    rates = np.rad2deg(crr.rates())
    for j, name in enumerate(names):
        ax.plot(crr.t[1:], rates[:, j], label=name)
    ax.set(title="CRR joint rates from position differences (Fig. 8)", xlabel="t [s]", ylabel="deg/s")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    labels = {
        "pinv": "pinv integration (Fig. 4)",
        "crr": "CRR, eq. (6) (Fig. 7)",
        "crr_log": "CRR, exact angular velocity",
        "crr_full": "CRR + full correction",
    }
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
