"""A campaign's report: pass rates with Wilson intervals, percentiles, plots (README, "Campaigns").

For each grid point (the runs of one combination of the grid's values, over samples and seeds):
  * the pass rate with its 95 % Wilson score interval (scipy.stats.binomtest(...).proportion_ci);
    a run that raised counts as not passed, an invalid run (parameters breaking a limit
    between them, with invalid = "skip") is not counted;
  * for every check: the median and the 5 % and 95 % percentiles of its value, and its own
    pass rate.
Written as ``campaign.json``, one plot per check in ``plots/`` (the value against each axis,
the limit drawn) and a one-page ``campaign.png``.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pyarrow as pa

#: Scatter plots show at most this many runs (every k-th run, so the picture is reproducible).
MAX_SCATTER = 20_000


def wilson(passed: int, n: int, confidence: float = 0.95) -> tuple[float, float] | tuple[None, None]:
    """The Wilson score interval of a pass rate ``passed / n`` (None for n = 0)."""
    if n == 0:
        return None, None
    from scipy import stats  # (scipy.stats takes ~0.4 s to import: only where a report is written)

    ci = stats.binomtest(passed, n).proportion_ci(confidence_level=confidence, method="wilson")
    return float(ci.low), float(ci.high)


def _floats(column) -> np.ndarray:
    """A numeric or boolean Arrow column as floats (True 1.0), NaN where it is null (Arrow's
    casts, without a Python object per row); a TypeError for any other type."""
    import pyarrow.compute as pc

    kind = column.type
    if not (
        pa.types.is_integer(kind) or pa.types.is_floating(kind) or pa.types.is_boolean(kind) or pa.types.is_null(kind)
    ):
        raise TypeError(f"a column of {kind} is not numbers")
    return pc.fill_null(pc.cast(column, pa.float64()), np.nan).to_numpy(zero_copy_only=False).astype(float)


def _column(table: pa.Table, name: str) -> np.ndarray:
    """A numeric column as floats, NaN where it is null (or absent: a check no run of a part had)."""
    if name not in table.column_names:
        return np.full(table.num_rows, np.nan)
    return _floats(table.column(name))


def _status(table: pa.Table) -> np.ndarray:
    return (
        table.column("status").to_numpy(zero_copy_only=False).astype(object)
        if table.num_rows
        else np.array([], dtype=object)
    )


def _percentiles(values: np.ndarray) -> dict:
    finite = values[np.isfinite(values)]
    if finite.size == 0:
        return {"median": None, "p5": None, "p95": None, "n": 0}
    p5, median, p95 = np.percentile(finite, [5, 50, 95])
    return {"median": float(median), "p5": float(p5), "p95": float(p95), "n": int(finite.size)}


def check_names(table: pa.Table) -> list[str]:
    return [c[len("check.") :] for c in table.column_names if c.startswith("check.")]


def summarize(spec, table: pa.Table, checks_meta: dict) -> dict:
    """campaign.json's content."""
    status = _status(table)
    point = _column(table, "point").astype(int) if table.num_rows else np.array([], int)
    counted = status != "invalid"
    names = check_names(table)
    values = {n: _column(table, f"check.{n}") for n in names}
    verdicts = {n: _column(table, f"pass.{n}") for n in names}  # 1, 0, NaN (not run)
    limits = {n: _column(table, f"limit.{n}") for n in names}

    def block(mask) -> dict:
        n = int(np.sum(mask & counted))
        passed = int(np.sum(mask & (status == "passed")))
        low, high = wilson(passed, n)
        out = {
            "runs": int(np.sum(mask)),
            "counted": n,
            "passed": passed,
            "failed": int(np.sum(mask & (status == "failed"))),
            "errors": int(np.sum(mask & (status == "error"))),
            "invalid": int(np.sum(mask & (status == "invalid"))),
            "pass_rate": passed / n if n else None,
            "pass_rate_ci95": [low, high],
            "checks": {},
        }
        for name in names:
            v = verdicts[name][mask & counted]
            judged = v[np.isfinite(v)]
            out["checks"][name] = {
                **_percentiles(values[name][mask & counted]),
                "pass_rate": float(judged.mean()) if judged.size else None,
            }
        return out

    points = []
    for p in range(spec.points):
        entry = {"point": p, "grid": {a.column: _plain(v) for a, v in zip(spec.grid, spec.grid_values(p), strict=True)}}
        entry.update(block(point == p))
        points.append(entry)
    checks = {}
    for name in names:
        finite = limits[name][np.isfinite(limits[name])]
        checks[name] = {
            **checks_meta.get(name, {}),
            "limit": float(np.median(finite)) if finite.size else None,
            "limits_differ": bool(finite.size and np.ptp(finite) > 0),
        }
    return {
        "scenario": spec.scenario.name,
        "mode": spec.mode,
        "spec": str(spec.path),
        "fingerprint": spec.fingerprint,
        "runs": spec.size,
        "rows": table.num_rows,
        "points": spec.points,
        "samples": spec.samples,
        "seeds_per_point": spec.replicates,
        "campaign_seed": spec.seed,
        "axes": [
            {
                "column": a.column,
                "kind": "grid" if a.values is not None else "random",
                **(
                    {"values": [_plain(v) for v in a.values]}
                    if a.values is not None
                    else {"distribution": a.distribution.name, **a.distribution.args}
                ),
            }
            for a in spec.axes
        ],
        "checks": checks,
        "overall": block(np.ones(table.num_rows, bool)),
        "by_point": points,
        "wall_s_total": float(np.nansum(_column(table, "wall_s"))) if table.num_rows else 0.0,
    }


def _plain(v):
    if isinstance(v, tuple):
        return [_plain(x) for x in v]
    return v


def format_summary(summary: dict) -> str:
    """The text table ``planbench sweep`` prints: one line per grid point, then each check's
    median [5 %, 95 %] over the whole campaign."""
    grid_columns = [a["column"] for a in summary["axes"] if a["kind"] == "grid"]
    head = " ".join(f"{c:>14}" for c in grid_columns)
    lines = [f"{'point':>5} {head} {'runs':>6} {'passed':>6} {'failed':>6} {'errors':>6} {'pass rate [95 % CI]':>24}"]
    for p in summary["by_point"]:
        cells = " ".join(f"{_cell(p['grid'][c]):>14}" for c in grid_columns)
        lines.append(
            f"{p['point']:>5} {cells} {p['counted']:>6} {p['passed']:>6} {p['failed']:>6} {p['errors']:>6} "
            f"{_rate(p):>24}"
        )
    o = summary["overall"]
    lines.append(
        f"{'all':>5} {' ' * len(head)} {o['counted']:>6} {o['passed']:>6} {o['failed']:>6} {o['errors']:>6} "
        f"{_rate(o):>24}" + (f"   ({o['invalid']} invalid, not counted)" if o["invalid"] else "")
    )
    lines.append("")
    lines.append(f"{'check':<24} {'unit':<7} {'limit':>10} {'median':>11} {'5 %':>11} {'95 %':>11} {'pass rate':>9}")
    for name, meta in summary["checks"].items():
        c = o["checks"][name]
        limit = "" if meta.get("limit") is None else f"{meta.get('comparison', '')}{meta['limit']:.4g}"
        rate = "" if c["pass_rate"] is None else f"{100 * c['pass_rate']:.1f} %"
        lines.append(
            f"{name:<24} {meta.get('unit', ''):<7} {limit:>10} {_num(c['median']):>11} {_num(c['p5']):>11} "
            f"{_num(c['p95']):>11} {rate:>9}"
        )
    return "\n".join(lines)


def _cell(v) -> str:
    return f"{v:.6g}" if isinstance(v, float) else str(v)


def _num(v) -> str:
    return "" if v is None else f"{v:.5g}"


def _rate(block: dict) -> str:
    if block["pass_rate"] is None:
        return "n/a"
    low, high = block["pass_rate_ci95"]
    return f"{100 * block['pass_rate']:.1f} % [{100 * low:.1f}, {100 * high:.1f}]"


# ------------------------------------------------------------------------------ worst runs


def worst_runs(table: pa.Table, k: int, checks_meta: dict) -> list[int]:
    """The run indices of the ``k`` worst simulated runs, for ``--rerun-worst``.

    A run's badness is the largest ratio of a check's value to its limit (the limit to the
    value for ">=" checks) over its checks, so a failed run has one above 1; a check that
    could not be evaluated is infinitely bad. Runs that raised or were invalid are left out
    (there is nothing to replay); ties go to the earlier run."""
    if table.num_rows == 0 or k <= 0:
        return []
    score = np.full(table.num_rows, -np.inf)
    status = _status(table)
    for name in check_names(table):
        value, limit = _column(table, f"check.{name}"), _column(table, f"limit.{name}")
        greater = checks_meta.get(name, {}).get("comparison", "<=").startswith(">")
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = (limit / value) if greater else (value / limit)
        ratio = np.where(np.isnan(value), np.inf, ratio)
        ratio = np.where(np.isfinite(limit) & (limit != 0), ratio, np.where(np.isnan(value), np.inf, -np.inf))
        score = np.maximum(score, np.nan_to_num(ratio, nan=np.inf, posinf=np.inf, neginf=-np.inf))
    score = np.where(np.isin(status, ["passed", "failed"]), score, -np.inf)
    order = sorted(range(table.num_rows), key=lambda i: (-score[i], i))
    runs = table.column("run").to_pylist()
    return [runs[i] for i in order[:k] if np.isfinite(score[i]) or score[i] == np.inf]


# ------------------------------------------------------------------------------ plots


def _axis_values(table: pa.Table, column: str):
    if column not in table.column_names:
        return np.full(table.num_rows, np.nan), None
    try:
        return _floats(table.column(column)), None
    except TypeError:
        pass
    raw = table.column(column).to_pylist()
    try:
        return np.array([np.nan if v is None else float(v) for v in raw]), None
    except (TypeError, ValueError):
        labels = sorted({str(v) for v in raw})
        return np.array([labels.index(str(v)) for v in raw], dtype=float), labels


def plot_checks(spec, table: pa.Table, summary: dict, folder) -> list:
    """One PNG per check in ``folder``: its value against each axis, the limit dashed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    counted = _status(table)
    keep = np.isin(counted, ["passed", "failed"])
    axis_values = {}
    stride = max(1, int(math.ceil(keep.sum() / MAX_SCATTER)))
    sel = np.flatnonzero(keep)[::stride]
    axes = spec.axes or []
    n = max(1, len(axes))
    # One figure for all checks, its plots made once: each check draws its data on them and
    # takes them away after its PNG (making plots and their ticks is most of a figure's cost).
    # One y scale per check (its tick labels on the first plot) and fixed margins
    # (tight_layout would measure every text).
    fig, plots = plt.subplots(1, n, figsize=(4.2 * n, 3.4), squeeze=False, sharey=True)
    fig.subplots_adjust(left=0.8 / (4.2 * n), right=1 - 0.1 / (4.2 * n), bottom=0.28, top=0.88, wspace=0.08)
    for name, meta in summary["checks"].items():
        value = _column(table, f"check.{name}")
        for ax_plot, axis in zip(plots[0], axes or [None], strict=True):
            if axis is None:
                x, labels = _column(table, "run"), None
                xlabel = "run"
            else:
                if axis.column not in axis_values:
                    axis_values[axis.column] = _axis_values(table, axis.column)
                x, labels = axis_values[axis.column]
                xlabel = axis.column + (f" ({axis.unit})" if axis.unit else "")
            ax_plot.plot(
                x[sel],
                value[sel],
                ".",
                alpha=0.35 if sel.size > 200 else 0.7,
                ms=3,
                color="tab:blue",
                label="runs" + (f" (every {stride}th)" if stride > 1 else ""),
            )
            if axis is not None and axis.values is not None:
                centres = np.unique(x[keep & np.isfinite(x)])
                med, lo, hi = [], [], []
                for c in centres:
                    v = value[keep & (x == c)]
                    v = v[np.isfinite(v)]
                    med.append(np.median(v) if v.size else np.nan)
                    lo.append(np.percentile(v, 5) if v.size else np.nan)
                    hi.append(np.percentile(v, 95) if v.size else np.nan)
                med, lo, hi = map(np.array, (med, lo, hi))
                ax_plot.errorbar(
                    centres,
                    med,
                    yerr=[med - lo, hi - med],
                    fmt="o-",
                    color="k",
                    ms=4,
                    capsize=3,
                    label="median, 5-95 %",
                )
            if meta.get("limit") is not None:
                ax_plot.axhline(
                    meta["limit"],
                    color="tab:red",
                    ls="--",
                    label=f"limit {meta.get('comparison', '')} {meta['limit']:.4g}",
                )
            if labels is not None:
                ax_plot.set_xticks(range(len(labels)), labels, rotation=30, fontsize=7)
            elif axis is not None and axis.values is not None:
                ax_plot.set_xticks(centres)
            else:
                ax_plot.xaxis.set_major_locator(MaxNLocator(4))  # few ticks: each is drawn as its own artist
            ax_plot.set_xlabel(xlabel)
            ax_plot.grid(alpha=0.3)
        plots[0][0].yaxis.set_major_locator(MaxNLocator(5))
        plots[0][0].set_ylabel(f"{name} ({meta.get('unit', '')})")
        legend = plots[0][0].legend(fontsize=7)
        fig.suptitle(f"{summary['scenario']}: {name}", fontsize=10)
        path = folder / f"{_safe(name)}.png"
        fig.savefig(path, dpi=90)
        paths.append(path)
        legend.remove()
        for ax_plot in plots[0]:
            for artist in [*ax_plot.lines, *ax_plot.collections]:
                artist.remove()
            ax_plot.containers.clear()
            ax_plot.relim()  # the data limits of the next check's data alone
    plt.close(fig)
    return paths


def _safe(name: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in name)


def plot_page(spec, table: pa.Table, summary: dict, path) -> None:
    """campaign.png: the pass rate per grid point with its Wilson interval, and each check's
    median and 5-95 % band per point with its limit."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    checks = list(summary["checks"])
    shown = checks[:11]
    cols = 3
    rows = 1 + int(math.ceil(len(shown) / cols))
    fig = plt.figure(figsize=(12, 2.6 * rows + 0.8))
    grid = fig.add_gridspec(rows, cols)
    top = fig.add_subplot(grid[0, :])
    points = summary["by_point"]
    x = np.arange(len(points))
    rate = np.array([np.nan if p["pass_rate"] is None else p["pass_rate"] for p in points])
    low = np.array([np.nan if p["pass_rate_ci95"][0] is None else p["pass_rate_ci95"][0] for p in points])
    high = np.array([np.nan if p["pass_rate_ci95"][1] is None else p["pass_rate_ci95"][1] for p in points])
    top.errorbar(x, 100 * rate, yerr=[100 * (rate - low), 100 * (high - rate)], fmt="o", capsize=4)
    labels = [", ".join(f"{k}={_cell(v)}" for k, v in p["grid"].items()) or "all" for p in points]
    top.set_xticks(x, labels, rotation=20 if len(points) > 4 else 0, fontsize=7)
    top.set_ylim(-5, 105)
    top.set_ylabel("pass rate (%), 95 % Wilson")
    top.grid(alpha=0.3)
    o = summary["overall"]
    top.set_title(
        f"{summary['scenario']} ({summary['mode']}): {o['counted']} runs, {o['passed']} passed, "
        f"{o['failed']} failed, {o['errors']} errors"
        + (f", {o['invalid']} invalid" if o["invalid"] else "")
        + f"; {summary['points']} points x {summary['samples']} samples x {summary['seeds_per_point']} seeds",
        fontsize=9,
    )
    for i, name in enumerate(shown):
        ax = fig.add_subplot(grid[1 + i // cols, i % cols])
        meta = summary["checks"][name]
        med = np.array(
            [np.nan if p["checks"].get(name, {}).get("median") is None else p["checks"][name]["median"] for p in points]
        )
        p5 = np.array(
            [np.nan if p["checks"].get(name, {}).get("p5") is None else p["checks"][name]["p5"] for p in points]
        )
        p95 = np.array(
            [np.nan if p["checks"].get(name, {}).get("p95") is None else p["checks"][name]["p95"] for p in points]
        )
        ax.errorbar(x, med, yerr=[med - p5, p95 - med], fmt="o-", ms=3, capsize=3, lw=1)
        if meta.get("limit") is not None:
            ax.axhline(meta["limit"], color="tab:red", ls="--", lw=1)
        ax.set_title(f"{name} ({meta.get('unit', '')}): median, 5-95 % per point", fontsize=8)
        ax.set_xticks(x, [str(i) for i in x], fontsize=6)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
    if len(checks) > len(shown):
        fig.text(0.5, 0.005, f"{len(checks) - len(shown)} more checks in plots/", ha="center", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def write(store, spec, table: pa.Table) -> dict:
    """campaign.json, campaign.png and plots/ of the table (each file written whole)."""
    import tempfile
    from pathlib import Path

    from planbench.campaign.store import write_atomic

    summary = summarize(spec, table, store.checks())
    write_atomic(store.path / "campaign.json", (json.dumps(summary, indent=1) + "\n").encode())
    with tempfile.TemporaryDirectory(prefix=".tmp-plots-", dir=store.path) as tmp:
        tmp = Path(tmp)
        plot_page(spec, table, summary, tmp / "campaign.png")
        write_atomic(store.path / "campaign.png", (tmp / "campaign.png").read_bytes())
        for p in plot_checks(spec, table, summary, tmp / "plots"):
            (store.path / "plots").mkdir(exist_ok=True)
            write_atomic(store.path / "plots" / p.name, p.read_bytes())
    return summary
