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


#: Rows of a report's time axis beyond which each plotted series is drawn as its envelope
#: (``envelope``): report.png's plots are about 500 pixels wide, so a long run's 10 Hz series
#: would put dozens of points on each pixel column and hold them all in memory to draw them.
REPORT_POINTS = 4_000


def envelope(values: np.ndarray, span: int) -> np.ndarray:
    """(2 m, ...) the smallest and the largest of ``values`` (n, ...) in each of its m spans of
    ``span`` rows, interleaved (the last span padded with its last row): what a line through
    every row shows at a pixel's width, peaks included."""
    n = values.shape[0]
    m = -(-n // span)
    if m * span > n:
        values = np.concatenate([values, np.repeat(values[-1:], m * span - n, axis=0)])
    values = values.reshape(m, span, *values.shape[1:])
    out = np.empty((2 * m, *values.shape[2:]), values.dtype)
    out[0::2], out[1::2] = values.min(axis=1), values.max(axis=1)
    return out


def envelope_times(t: np.ndarray, span: int) -> np.ndarray:
    """(2 m,) the times ``envelope``'s rows are drawn at: each span's first row and its middle."""
    first = np.arange(0, t.size, span)
    out = np.empty(2 * first.size)
    out[0::2], out[1::2] = t[first], t[np.minimum(first + span // 2, t.size - 1)]
    return out


def envelope_of_parts(parts, span: int) -> np.ndarray:
    """``envelope`` of the rows of ``parts`` (arrays (m_i, ...), in order) joined, made a part
    at a time: only a part and less than a span of rows are held."""
    out, carry = [], None
    for part in parts:
        if carry is not None and carry.shape[0]:
            part = np.concatenate([carry, part])
        whole = part.shape[0] // span * span
        if whole:
            out.append(envelope(part[:whole], span))
        carry = part[whole:]
    if carry is not None and carry.shape[0]:
        out.append(envelope(carry, span))
    return np.concatenate(out)


def _parts(values):
    """A series' rows a part at a time: a spooled series' chunks (``logfile.LoggedSeries``), or
    an array whole."""
    return values.parts() if hasattr(values, "parts") else iter([np.asarray(values)])


def fast_report(ts: dict, t: np.ndarray, checks, path, tension_min: float) -> None:
    """report.png of a FAST run: feed and cabin errors, cable tensions, Stewart legs, wind.
    ``ts``: timeseries (arrays, or series spooled to disk, read a chunk at a time); a run of
    more than REPORT_POINTS rows is drawn as envelopes."""
    span = -(-t.size // (REPORT_POINTS // 2)) if t.size > REPORT_POINTS else 1

    def rows(*series, of=None) -> np.ndarray:
        """The rows drawn of ``series`` (of ``of(*series)`` row by row, when given)."""
        parts = (of(*p) if of else p[0] for p in zip(*(_parts(s) for s in series), strict=True))
        return np.concatenate(list(parts)) if span == 1 else envelope_of_parts(parts, span)

    observing = rows(ts["observing"]).astype(bool)
    if span > 1:  # a span observing anywhere is drawn observing
        observing = np.repeat(observing[1::2], 2)
        t = envelope_times(t, span)
    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5))
    for ax in axes.flat:
        ax.fill_between(t, 0, 1, where=observing, transform=ax.get_xaxis_transform(), color="0.93", lw=0)
    ax = axes[0, 0]
    ax.plot(t, rows(ts["feed_error_mm"]), lw=0.7, label="feed |actual - planned|")
    cabin = rows(ts["cabin_pos_actual"], ts["cabin_pos_planned"], of=lambda a, b: 1e3 * np.linalg.norm(a - b, axis=1))
    ax.plot(t, cabin, lw=0.7, label="cabin origin")
    ax.set(title="position errors (grey: observing)", xlabel="t [s]", ylabel="mm")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    tension, planned = rows(ts["cable_tension"]), rows(ts["cable_tension_planned"])
    for j, name in enumerate(ts["cable_names"]):
        (line,) = ax.plot(t, tension[:, j] / 1e3, lw=0.7, label=str(name))
        ax.plot(t, planned[:, j] / 1e3, "--", color=line.get_color(), lw=0.6)
    ax.axhline(tension_min / 1e3, color="r", lw=0.8)
    ax.set_ylim(bottom=0.0)
    ax.set(title="cable tensions (dashed: planned statics), T_min in red", xlabel="t [s]", ylabel="kN")
    ax.legend(fontsize=8, ncol=3)
    ax = axes[1, 0]
    legs = rows(ts["stewart_leg"])
    for j in range(legs.shape[1]):
        ax.plot(t, 1e3 * legs[:, j], lw=0.7, label=f"leg{j + 1}")
    ax.set(title="Stewart leg length changes", xlabel="t [s]", ylabel="mm")
    ax.legend(fontsize=8, ncol=3)
    ax = axes[1, 1]
    if "wind_speed" in ts:
        ax.plot(t, rows(ts["wind_speed"]), color="0.4", lw=0.6, label="wind speed [m/s]")
        twin = ax.twinx()
        drag = rows(ts["wind_force"], of=lambda f: np.linalg.norm(f, axis=1))
        twin.plot(t, drag / 1e3, lw=0.6, label="drag on cabin and cables")
        twin.set_ylabel("kN")
        twin.legend(fontsize=8, loc="upper right")
        ax.legend(fontsize=8, loc="upper left")
    ax.set(title="wind", xlabel="t [s]", ylabel="m/s")
    finish(fig, axes, axes[0, 1], checks, path, top=False)  # below the tensions, above 0
