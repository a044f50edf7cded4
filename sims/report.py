"""Plots shared by every mechanism (matplotlib, Agg): plan.png of a planned motion, the checks' text
box and the layout of a report; each mechanism draws its own report.png (sims/<mechanism>/report.py)."""

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
        strict=True,
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


def finish(fig, axes, text_ax, checks, path, top: bool) -> None:
    """Checks in a box on ``text_ax``, grids, layout, save at 90 dpi, close."""
    text_ax.text(
        0.02,
        0.97 if top else 0.03,
        checks_text(checks),
        transform=text_ax.transAxes,
        va="top" if top else "bottom",
        fontsize=7,
        family="monospace",
        bbox=dict(facecolor="white", alpha=0.8),
    )
    for a in axes.flat:
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
