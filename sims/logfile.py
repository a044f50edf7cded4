"""A run's log on disk: the state at every control tick, streamed in chunks as the run goes.

The runner (``planbench.runner.simulate``) copies each tick's state into a fixed-size chunk buffer
(``ChunkWriter``: CHUNK_TICKS rows) and appends every full chunk to ``log.arrow``, an Arrow
IPC *file* (https://arrow.apache.org/docs/format/Columnar.html#ipc-file-format): one record
batch per chunk, written with plain ``write`` calls as soon as the chunk is full. The memory a
run's log takes is the buffer's, whatever the run's length.

Columns: ``t`` (float64), then ``qpos``, ``qvel``, ``act``, ``ctrl``, ``actuator_force``,
``sensordata``, ``mocap_pos``, ``mocap_quat``, each a fixed-size list of float64 per tick (a
row of the array, flattened); an array of width 0 (no activations, no mocap bodies) has no
column. The schema's metadata ``planbench.log`` (JSON) holds each array's per-tick shape.

Complete or not: the Arrow file's footer is written only when the run closes its log after
the last tick. A log without it (the run was killed, or is still running) reads as
incomplete: ``read_log`` returns the chunks written so far, with ``complete`` False.

Reading (``read_log(path)``): ``log.column("qpos")`` is a whole array (n, nq);
``log.chunks()`` yields one dict of arrays per chunk, read from the file one at a time, for
computations that need not hold the whole run at once.
"""

from __future__ import annotations

import json
import os
import tempfile
import weakref
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa

#: The file name of a run's log inside its output directory.
LOG_FILE = "log.arrow"
#: Ticks per chunk (a record batch of the file). FAST at 100 Hz: ~5 MB per chunk.
CHUNK_TICKS = 4096
#: The per-tick arrays of a log, in the file's order (``t`` is the first column).
ARRAYS = ("qpos", "qvel", "act", "ctrl", "actuator_force", "sensordata", "mocap_pos", "mocap_quat")
_META = b"planbench.log"
_FORMAT = 1
#: The first 8 bytes of an Arrow IPC file ("ARROW1" and two bytes of padding); a stream of
#: the same messages follows them, readable up to its last complete record batch.
_MAGIC_BYTES = 8


def model_shapes(model) -> dict[str, tuple[int, ...]]:
    """Each logged array's per-tick shape for a compiled ``mujoco.MjModel``."""
    return {
        "qpos": (model.nq,),
        "qvel": (model.nv,),
        "act": (model.na,),
        "ctrl": (model.nu,),
        "actuator_force": (model.nu,),
        "sensordata": (model.nsensordata,),
        "mocap_pos": (model.nmocap, 3),
        "mocap_quat": (model.nmocap, 4),
    }


def _width(shape) -> int:
    return int(np.prod(shape, dtype=np.int64))


def _schema(shapes: dict) -> pa.Schema:
    fields = [pa.field("t", pa.float64())]
    fields += [
        pa.field(name, pa.list_(pa.float64(), _width(shape))) for name, shape in shapes.items() if _width(shape) > 0
    ]
    meta = {"format": _FORMAT, "shapes": {name: list(shape) for name, shape in shapes.items()}}
    return pa.schema(fields, metadata={_META: json.dumps(meta).encode()})


class ChunkWriter:
    """The buffer the runner records into and the file it streams to.

    ``buffers[name]`` are arrays of ``HISTORY + chunk`` rows: row ``j`` of the run is buffer
    row ``j - base``. When a row would fall past the buffer's end, ``flush`` appends the
    chunk (rows ``HISTORY`` on) to the file and keeps its last HISTORY rows at the top, so
    that code looking a few ticks back (the runner's divergence scan) still finds them.
    ``close(n)`` writes the rows up to run row ``n`` (exclusive) and the file's footer.

    ``block``: names of arrays whose buffers share one row of ``self.block`` (rows, widths
    summed), side by side in that order, so that one copy fills them all (the runner's
    ``mj_getState`` of qpos, qvel, act and the mocap poses); their ``buffers`` are views of
    it."""

    def __init__(
        self, path, shapes: dict, times: np.ndarray, chunk: int = CHUNK_TICKS, history: int = 0, block: tuple = ()
    ):
        if chunk < 1:
            raise ValueError(f"chunk of {chunk} ticks: at least 1")
        self.path = Path(path)
        self.shapes = dict(shapes)
        self.times = times
        self.chunk, self.history = int(chunk), int(history)
        rows = self.history + self.chunk
        self.block = np.zeros((rows, sum(_width(self.shapes[name]) for name in block)))
        self.buffers, at = {}, 0
        for name in block:
            width = _width(self.shapes[name])
            view = self.block[:, at : at + width]
            view.shape = (rows, *self.shapes[name])  # in place: raises rather than copy
            self.buffers[name], at = view, at + width
        self.buffers.update(
            {name: np.zeros((rows, *shape)) for name, shape in self.shapes.items() if name not in self.buffers}
        )
        self.base = -self.history  # run row of buffer row 0
        self.written = 0  # run rows in the file
        self.schema = _schema(self.shapes)
        self._sink = pa.OSFile(str(self.path), "wb")  # unbuffered: a written chunk is in the file
        self._writer = pa.ipc.new_file(self._sink, self.schema)
        # An empty batch now puts the schema in the file: a run killed before its first
        # chunk leaves a log of 0 ticks, readable, incomplete.
        self._writer.write_batch(pa.record_batch([pa.array([], f.type) for f in self.schema], schema=self.schema))
        self.closed = False
        self.temporary = False  # (temporary_writer)
        self._read = None  # the LogFile read back

    @property
    def end(self) -> int:
        """One past the last run row the buffer can hold now."""
        return self.base + self.history + self.chunk

    def flush(self) -> None:
        """Append the buffered chunk (a full one) and move the buffer on by a chunk."""
        self._write(self.end)
        h = self.history
        for a in self.buffers.values():
            if h:
                a[:h] = a[self.chunk : self.chunk + h]  # (the block's views move the block)
            a[h:] = 0.0  # a row no tick writes reads 0, as in a fresh buffer
        self.base += self.chunk

    def _write(self, stop: int) -> None:
        lo, hi = self.written - self.base, stop - self.base
        if hi <= lo:
            return
        self._write_rows({name: a[lo:hi] for name, a in self.buffers.items()}, stop)

    def _write_rows(self, arrays: dict, stop: int) -> None:
        """Append ``arrays`` ({name: rows}), the run's rows up to ``stop``, as a chunk."""
        columns = [pa.array(self.times[self.written : stop])]
        for name, shape in self.shapes.items():
            width = _width(shape)
            if width:
                flat = np.ascontiguousarray(arrays[name]).reshape(-1)
                columns.append(pa.FixedSizeListArray.from_arrays(pa.array(flat), width))
        self._writer.write_batch(pa.record_batch(columns, schema=self.schema))
        self.written = stop

    def append(self, arrays: dict) -> None:
        """Append the next rows given whole ({name: (m, *shape)} of every array), as a chunk
        of the file, past the buffer (for a writer that writes no row through it)."""
        m = next(iter(arrays.values())).shape[0]
        self._write_rows(arrays, self.written + m)
        self.base = self.written - self.history

    def row(self, name: str, i: int) -> np.ndarray:
        """The buffer's row of run row ``i`` of the array ``name``, to write the tick's values
        in (rows in order: the first row past the buffer appends the full chunk first)."""
        if i >= self.end:
            self.flush()
        return self.buffers[name][i - self.base]

    def read_back(self, rows: int) -> LogFile:
        """``close(rows)`` and the log read back, once (later calls return it); a temporary
        log's file (``temporary_writer``) is then removed, the open file keeping its data."""
        if self._read is None:
            if not self.closed:
                self.close(rows)
            self._read = read_log(self.path)
            if self.temporary:
                remove_quietly(self.path)
        return self._read

    def close(self, rows: int) -> None:
        """Write the run's rows up to ``rows`` (exclusive) not yet written, and the footer
        that marks the log complete."""
        self._write(rows)
        self._writer.close()
        self._sink.close()
        self.closed = True

    def abandon(self) -> None:
        """Close the file without its footer (the log stays incomplete)."""
        if not self.closed:
            self._sink.close()
            self.closed = True


@dataclass
class LogFile:
    """A log read back (``read_log``): where each chunk (an Arrow record batch) starts in the
    file, its rows, whether the log is complete, and each array's per-tick shape. Chunks are
    read from the file when asked for (the file stays open: a log removed from the file
    system meanwhile still reads)."""

    path: Path
    complete: bool
    shapes: dict
    schema: pa.Schema = field(repr=False)
    source: object = field(repr=False)
    offsets: list = field(repr=False)
    rows: list = field(repr=False)

    @property
    def n(self) -> int:
        """Ticks in the log."""
        return sum(self.rows)

    @property
    def num_chunks(self) -> int:
        return len(self.rows)

    @property
    def names(self) -> tuple:
        return ("t", *self.shapes)

    def batch(self, k: int) -> pa.RecordBatch:
        """Chunk ``k`` as an Arrow record batch (read from the file now)."""
        self.source.seek(self.offsets[k])
        return pa.ipc.read_record_batch(pa.ipc.read_message(self.source), self.schema)

    def _array(self, batch: pa.RecordBatch, name: str) -> np.ndarray:
        if name == "t":
            return batch.column(0).to_numpy()
        shape = self.shapes[name]
        if _width(shape) == 0:
            return np.zeros((batch.num_rows, *shape))
        values = batch.column(name).flatten().to_numpy()
        return values.reshape(batch.num_rows, *shape)

    def chunk(self, k: int, names=None) -> dict[str, np.ndarray]:
        """Chunk ``k``'s arrays (all, or ``names``), read-only."""
        for name in names or ():
            self._known(name)
        batch = self.batch(k)
        return {name: self._array(batch, name) for name in (names or self.names)}

    def chunks(self, names=None):
        """Each chunk's arrays in turn (``chunk``): the whole run, one chunk in memory."""
        for k in range(self.num_chunks):
            yield self.chunk(k, names)

    def every(self, name: str, stride: int) -> np.ndarray:
        """Rows 0, stride, 2 stride, ... of the array ``name``, read a chunk at a time."""
        self._known(name)
        parts, start = [], 0
        for k, rows in enumerate(self.rows):
            parts.append(self._array(self.batch(k), name)[-start % stride :: stride].copy())
            start += rows
        shape = () if name == "t" else tuple(self.shapes[name])
        return np.concatenate(parts) if parts else np.zeros((0, *shape))

    def span(self, name: str, start: int, stop: int) -> np.ndarray:
        """Rows ``start`` to ``stop`` (exclusive) of the array ``name``, read from the chunks
        that hold them."""
        self._known(name)
        parts, first = [], 0
        for k, rows in enumerate(self.rows):
            if first < stop and start < first + rows:
                part = self._array(self.batch(k), name)
                parts.append(part[max(start - first, 0) : stop - first])
            first += rows
        shape = () if name == "t" else tuple(self.shapes[name])
        return np.concatenate(parts) if parts else np.zeros((0, *shape))

    def _known(self, name: str) -> None:
        if name != "t" and name not in self.shapes:
            raise KeyError(f"no array {name!r} in {self.path}; it has {', '.join(self.names)}")

    def column(self, name: str) -> np.ndarray:
        """The whole array ``name`` (a copy in memory, writable)."""
        self._known(name)
        shape = () if name == "t" else tuple(self.shapes[name])
        out = np.empty((self.n, *shape))
        row = 0
        for k in range(self.num_chunks):
            part = self._array(self.batch(k), name)
            out[row : row + part.shape[0]] = part
            row += part.shape[0]
        return out

    def copy_to(self, path) -> None:
        """Write this log to ``path``, a chunk at a time; with the footer only if this log
        has one (complete)."""
        sink = pa.OSFile(str(path), "wb")
        writer = pa.ipc.new_file(sink, self.schema)
        writer.write_batch(pa.record_batch([pa.array([], f.type) for f in self.schema], schema=self.schema))
        for k in range(self.num_chunks):
            writer.write_batch(self.batch(k))
        if self.complete:
            writer.close()
        sink.close()

    def to_dict(self) -> dict[str, np.ndarray]:
        """Every array, whole."""
        return {name: self.column(name) for name in self.names}


class LoggedSeries:
    """Every ``stride``-th row of one array of a LogFile, as a whole array only when asked for
    (``np.asarray``): a log's arrays in timeseries.npz, and the series an evaluation keeps at
    every stride-th tick of a long run, spooled to a temporary log rather than held
    (``save_timeseries`` writes it a chunk at a time; a report reads one series at a time).
    ``dtype``: the series' own type (a log stores float64; booleans and small integers come
    back exactly); ``scale``: a factor its values are multiplied by as they are read (a unit's
    change: mm of a series logged in m)."""

    def __init__(self, log: LogFile, name: str, dtype=float, scale: float | None = None, stride: int = 1):
        log._known(name)
        self.log, self.name, self.dtype, self.scale, self.stride = log, name, np.dtype(dtype), scale, stride
        self.shape = (len(range(0, log.n, stride)), *(() if name == "t" else tuple(log.shapes[name])))

    @property
    def ndim(self) -> int:
        return len(self.shape)

    def __len__(self) -> int:
        return self.shape[0]

    def __rmul__(self, factor: float) -> LoggedSeries:
        """``factor * series``: the series scaled as it is read (float series only)."""
        if self.dtype != np.dtype(float) or self.scale is not None:
            return NotImplemented
        return LoggedSeries(self.log, self.name, self.dtype, float(factor), self.stride)

    def _values(self, values: np.ndarray) -> np.ndarray:
        return values.astype(self.dtype) if self.scale is None else self.scale * values

    def parts(self):
        """Each chunk's rows (every stride-th of the log's) in turn, of ``dtype``."""
        start = 0
        for part in self.log.chunks([self.name]):
            rows = part[self.name]
            yield np.ascontiguousarray(self._values(rows[-start % self.stride :: self.stride]))
            start += rows.shape[0]

    def __getitem__(self, key) -> np.ndarray:
        return np.asarray(self)[key]

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        whole = self.log.column(self.name) if self.stride == 1 else self.log.every(self.name, self.stride)
        values = self._values(whole)
        return values if dtype is None else values.astype(dtype)


def read_log(path) -> LogFile:
    """Read a run's log (``log.arrow``, or the output directory that holds it).

    A complete log has the Arrow file's footer; one without (the run was killed or is still
    running) holds its chunks up to the last whole one and has ``complete`` False. This
    reads the file once through (one chunk in memory at a time) to find its chunks."""
    path = Path(path)
    if path.is_dir():
        path = path / LOG_FILE
    source = pa.OSFile(str(path), "rb")
    try:
        pa.ipc.open_file(source)  # its footer: written only after the last chunk
        complete = True
    except (pa.ArrowInvalid, OSError):
        complete = False
    source.seek(_MAGIC_BYTES)
    try:
        stream = pa.ipc.open_stream(source)
    except (pa.ArrowInvalid, OSError) as e:
        raise ValueError(f"{path} is not a planbench log (not even its schema could be read: {e})") from None
    schema, offsets, rows = stream.schema, [], []
    while True:
        at = source.tell()
        try:
            batch = stream.read_next_batch()
        except StopIteration:
            break
        except (pa.ArrowInvalid, OSError):  # a chunk cut short by the kill
            break
        if batch.num_rows:
            offsets.append(at)
            rows.append(batch.num_rows)
    try:
        meta = json.loads(schema.metadata[_META])
    except (KeyError, TypeError, ValueError):
        raise ValueError(f"{path} is an Arrow file but not a planbench log (no {_META.decode()} metadata)") from None
    shapes = {name: tuple(shape) for name, shape in meta["shapes"].items()}
    return LogFile(path, complete, shapes, schema, source, offsets, rows)


def temporary_writer(
    shapes: dict, times: np.ndarray, chunk: int = CHUNK_TICKS, prefix: str = "planbench-log-"
) -> ChunkWriter:
    """A ChunkWriter (no history) to a log file in a temporary directory of its own, removed
    when the writer is dropped or read back (``ChunkWriter.read_back``): per-tick records of a
    run's parts (the sensors' estimates, the plant's loads) kept on disk, not in memory."""
    path = Path(tempfile.mkdtemp(prefix=prefix)) / LOG_FILE
    writer = ChunkWriter(path, shapes, times, chunk)
    writer.temporary = True
    weakref.finalize(writer, remove_quietly, path)
    return writer


def remove_quietly(path) -> None:
    """Remove a log file (and its folder, if that is then empty) if it is still there."""
    path = Path(path)
    try:
        os.unlink(path)
        os.rmdir(path.parent)
    except OSError:
        pass
