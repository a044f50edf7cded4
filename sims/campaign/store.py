"""A campaign's directory: its spec, its results table, its runs (README, "Campaigns").

    DIR/planbench-campaign.json   what the campaign is (the spec's fingerprint, its size); a
                                  resumed campaign must have the same fingerprint
    DIR/spec.toml                 the spec as given
    DIR/table/part-*.parquet      the results table, one part per finished chunk of runs,
                                  each written whole (a temporary file, fsync, rename): a kill
                                  loses only the runs in flight
    DIR/checks.json               each check's unit and comparison
    DIR/runs/NNNNNN/              a simulated run's summary.json (timeseries and video when asked)
    DIR/results.parquet           the whole table, sorted by run, rewritten at the end
    DIR/campaign.json, campaign.png, plots/, worst/   the report (planbench.campaign.report)

planbench never writes into a directory it did not create as a campaign (or an empty one),
and one campaign at a time holds a directory (a lock file beside it, as planbench.outputs).
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import time
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

from planbench import outputs
from planbench.outputs import OutputError

STATE = outputs.CAMPAIGN_STATE  # "planbench-campaign.json"
TABLE = "table"
RUNS = "runs"
RESULTS = "results.parquet"
CHECKS = "checks.json"
_TMP = ".tmp-"


def _fsync_dir(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def write_atomic(path: Path, data) -> None:
    """``data`` (bytes, or a function that writes to the binary file it is given) into
    ``path``: a temporary file beside it, fsync, rename (never half-written)."""
    tmp = path.with_name(f"{_TMP}{path.name}.{os.getpid()}")
    try:
        with open(tmp, "wb") as f:
            if isinstance(data, bytes):
                f.write(data)
            else:
                data(f)
            f.flush()
            os.fsync(f.fileno())
        with outputs.signals_deferred():
            os.replace(tmp, path)
            _fsync_dir(path.parent)
    except BaseException:  # an interrupt or a full disk: the half-written file goes
        with outputs.signals_deferred():
            tmp.unlink(missing_ok=True)
        raise


class CampaignDir(outputs._Target):
    """``--out`` of ``planbench sweep``: validated on construction (nothing written), then
    ``with store.reserved():`` locked, and ``open(spec)`` creates or resumes it."""

    what = "campaign dir"

    def __init__(self, raw, option: str = "--out"):
        super().__init__(raw, option)
        self._checks: dict = {}  # checks.json as last written by this process
        path = self.path
        real = Path(os.path.realpath(path))
        cwd = Path(os.path.realpath(os.getcwd()))
        if real == Path(real.anchor) or real == Path(os.path.realpath(Path.home())) or cwd.is_relative_to(real):
            raise OutputError(
                f"{self.what} {path} is the root, the home or the current directory (or holds it); "
                "choose a new directory"
            )
        # A run's files lie in DIR/runs/NNNNNN/ (staged beside it first), the longest deepest.
        outputs._check_lengths(
            self.what, path, len(f"{RUNS}/000000/") + len(outputs.STAGING_PREFIX) + 8 + 1 + outputs._LONGEST_INNER
        )
        if os.path.islink(path):
            raise OutputError(f"{self.what} {path} is a symbolic link; give the directory itself")
        if os.path.lexists(path):
            if not path.is_dir():
                raise OutputError(f"{self.what} {path} exists and is not a directory")
            if not (path / STATE).is_file() and any(path.iterdir()):
                raise OutputError(
                    f"{self.what} {path} is not empty and is not a planbench campaign (no {STATE}); "
                    f"choose another {option}"
                )
            if not os.access(path, os.W_OK | os.X_OK):
                raise OutputError(f"{self.what} {path} is not writable")

    @property
    def table_dir(self) -> Path:
        return self.path / TABLE

    def state(self) -> dict | None:
        try:
            return json.loads((self.path / STATE).read_text())
        except (OSError, ValueError):
            return None

    def open(self, spec, spec_text: str) -> None:
        """Create the campaign, or check that the one here has the same spec (OutputError)."""
        state = self.state()
        if state is not None:
            if state.get("fingerprint") != spec.fingerprint:
                raise OutputError(
                    f"{self.what} {self.path} holds a campaign of another spec (or of a changed "
                    f"scenario file); its spec is {self.path / 'spec.toml'}. Resume it with that spec, "
                    f"or choose another {self.option}"
                )
            self._remove_temporaries()
            return
        self.path.mkdir(exist_ok=True)
        (self.path / TABLE).mkdir(exist_ok=True)
        (self.path / RUNS).mkdir(exist_ok=True)
        write_atomic(self.path / "spec.toml", spec_text.encode())
        write_atomic(
            self.path / STATE,
            (
                json.dumps(
                    {
                        "written_by": "planbench",
                        "fingerprint": spec.fingerprint,
                        "scenario": spec.scenario.name,
                        "mode": spec.mode,
                        "runs": spec.size,
                        "created_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                        "versions": outputs.software_versions(),
                    },
                    indent=1,
                )
                + "\n"
            ).encode(),
        )

    def _remove_temporaries(self) -> None:
        """Half-written parts of a killed campaign (only planbench's own temporary names)."""
        for folder in (self.path, self.table_dir):
            for entry in folder.glob(f"{_TMP}*"):
                with contextlib.suppress(OSError):
                    if entry.is_dir() and not entry.is_symlink():
                        shutil.rmtree(entry)  # the report's plots, staged
                    else:
                        entry.unlink()

    # ---------------------------------------------------------------- the table

    def part_files(self) -> list[Path]:
        return sorted(self.table_dir.glob("part-*.parquet"))

    def done(self) -> set[int]:
        """Indices of the runs that have a row."""
        return set(self.done_array().tolist())

    def done_array(self):
        """Indices of the runs that have a row, a sorted int64 array."""
        import numpy as np

        parts = [pq.read_table(part, columns=["run"]).column("run").to_numpy() for part in self.part_files()]
        return np.unique(np.concatenate(parts)) if parts else np.zeros(0, dtype=np.int64)

    def append(self, rows, checks: dict) -> None:
        """One part file of ``rows`` (dicts, or an Arrow table: a chunk of the columnar
        path) written whole, and new checks' units."""
        if not len(rows):
            return
        if any(name not in self._checks for name in checks):
            self._checks = {**self.checks(), **checks}
            write_atomic(self.path / CHECKS, (json.dumps(self._checks, indent=1, sort_keys=True) + "\n").encode())
        if isinstance(rows, pa.Table):
            table = rows
            first, last = table.column("run")[0].as_py(), table.column("run")[-1].as_py()
        else:
            from planbench.campaign.worker import rows_table

            first, last = rows[0]["run"], rows[-1]["run"]
            table = rows_table(rows)
        write_atomic(self.table_dir / f"part-{first:08d}-{last:08d}.parquet", lambda f: pq.write_table(table, f))

    def checks(self) -> dict:
        try:
            return json.loads((self.path / CHECKS).read_text())
        except (OSError, ValueError):
            return {}

    def table(self) -> pa.Table:
        """Every row, sorted by run."""
        parts = [pq.read_table(p) for p in self.part_files()]
        if not parts:
            return pa.table({"run": pa.array([], pa.int64())})
        table = pa.concat_tables(parts, promote_options="permissive")
        # The parts, in the order of their names, are mostly in run order already (a campaign
        # run without a break): sorting then would only copy the table.
        runs = table.column("run").to_numpy()
        if (runs[1:] > runs[:-1]).all():
            return table
        return table.sort_by("run")

    def write_results(self, table: pa.Table) -> Path:
        # Written straight to the file: the table's bytes are not held twice in memory.
        write_atomic(self.path / RESULTS, lambda f: pq.write_table(table, f))
        return self.path / RESULTS

    # ---------------------------------------------------------------- per-run outputs

    def run_dir(self, index: int) -> Path:
        return self.path / RUNS / f"{index:06d}"

    def write_run_files(self, index: int, files: dict, scenario: str) -> None:
        """A run's files into DIR/runs/NNNNNN, staged and swapped in whole (planbench.outputs)."""
        if not files:
            return
        target = outputs.OutputDir(self.run_dir(index), kind="campaign run")
        with target.reserved(), target.staging({"scenario": scenario, "run": index}) as tmp:
            for name, data in files.items():
                (tmp / name).write_bytes(data)
