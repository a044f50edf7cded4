"""Where a campaign's chunks run: a local process pool, or Ray (README, "Campaigns").

Both take the same ``Context`` and chunks of ``RunTask``s (plain data, planbench.campaign.worker)
and yield each chunk's result as it finishes, in any order; the campaign writes the rows.

``LocalEngine`` is a ``concurrent.futures.ProcessPoolExecutor`` whose workers are *spawned*
(not forked): a fork would copy a parent that may hold an EGL context, MuJoCo's threads or
an open Ray connection. ``RayEngine`` submits each chunk as a Ray task (``num_cpus=1``,
no retries: a run is not repeated behind the campaign's back) to the cluster at ``address``
(or ``RAY_ADDRESS``), or to a local Ray instance it starts when neither is given.
"""

from __future__ import annotations

import collections
import concurrent.futures as cf
import itertools
import multiprocessing
import os

from planbench import outputs
from planbench.campaign import worker

ENGINES = ("local", "ray")


def _lost(context, chunk, why: str) -> dict:
    """Rows of a chunk whose worker died: status "error" with the reason."""
    if isinstance(chunk, worker.ColumnTask):
        return worker.lost_columns(context, chunk, why)
    rows = [
        {**worker.row_of(context, task), "status": "error", "passed": None, "error": why, "wall_s": 0.0, "sim_s": None}
        for task in chunk
    ]
    return {"rows": rows, "checks": {}, "files": {}}


def _init_worker(parent: int | None = None, context: worker.Context | None = None):
    contain_worker(parent)
    if parent == os.getpid():  # an in-process stand-in for a pool (tests)
        return
    # What every run needs, made as the worker starts (while the driver checks the runs and
    # opens the campaign's directory): the scenario's mechanism and the base parameters
    # (``worker.prepare``), and for simulated runs the pipeline and MuJoCo. What fails here
    # fails again in the first chunk, which reports it in its rows (an initializer's error
    # would break the pool instead).
    try:
        if context is None or context.mode == "simulate":
            import planbench.pipeline  # noqa: F401
        import planbench.scenarios  # noqa: F401

        if context is not None:
            worker.prepare(context)
    except Exception:  # noqa: BLE001
        pass


def _warm() -> None:
    """A pool's first task per worker: it makes the pool spawn its workers now."""


#: How often a worker without PR_SET_PDEATHSIG looks whether its driver still lives, s.
PARENT_POLL_S = 1.0
_PR_SET_PDEATHSIG = 1


def contain_worker(parent: int | None) -> None:
    """Make this process a quiet worker of the process ``parent``.

    Ctrl-C at a terminal signals the whole process group: the driver alone answers it (it
    ends its workers and prints one line), so a worker ignores SIGINT and SIGHUP, and SIGTERM
    (the driver's way to end it) ends it silently. The driver spawns its workers with those
    signals blocked (``planbench.outputs.signals_deferred``), so none arrives before this. And a
    worker ends with its driver, even one killed by SIGKILL: the kernel sends it SIGKILL when
    the driver dies (Linux PR_SET_PDEATHSIG), elsewhere a thread that looks every
    PARENT_POLL_S whether the parent's pid changed. Without that, orphaned workers (and the
    resource tracker they keep alive) would hold the caller's stdout open.
    """
    import signal
    import threading

    from planbench.outputs import INTERRUPT_SIGNALS

    if parent == os.getpid():  # an in-process stand-in for a pool (tests): this is the driver
        return
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    # tqdm's default lock is a named multiprocessing semaphore; a worker ended by SIGTERM never
    # unlinks it and the resource tracker reports it as leaked. A worker's bars need no lock
    # shared with other processes.
    from tqdm import tqdm

    tqdm.set_lock(threading.RLock())
    signal.pthread_sigmask(signal.SIG_UNBLOCK, INTERRUPT_SIGNALS)
    if parent is None:
        return
    armed = False
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        armed = libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent:  # the driver died before the kernel was told
        os._exit(1)
    if armed:
        return

    def watch():
        while os.getppid() == parent:
            threading.Event().wait(PARENT_POLL_S)
        os._exit(1)

    threading.Thread(target=watch, name="planbench-parent-watch", daemon=True).start()


def _run_in_worker(context, chunk):
    return worker.run_chunk(context, chunk)


class LocalEngine:
    """A pool of ``workers`` spawned processes (default: the machine's cores).

    A campaign (``sweep(..., engine="local")``) starts its own pool and ends it. A caller
    that runs several campaigns in one process may hold one pool across them, as a Ray
    cluster is held: ``with LocalEngine(2) as engine: sweep(a, ..., engine=engine);
    sweep(b, ..., engine=engine)``; its workers start once and keep what they imported
    (planbench, MuJoCo, the mechanisms and plug-ins of earlier campaigns), and end when the
    ``with`` block does.
    """

    name = "local"

    def __init__(self, workers: int | None = None):
        self.workers = workers or os.cpu_count() or 1
        self._pool = None  # started by ``start``; taken by ``run``, which gives it back when kept
        self.kept = False  # held by the caller across campaigns (``with``)

    def __enter__(self):
        self.start()
        self.kept = True
        return self

    def __exit__(self, *exc) -> None:
        self.kept = False
        self.close()

    def _new_pool(self, context: worker.Context | None):
        return cf.ProcessPoolExecutor(
            max_workers=self.workers,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_init_worker,
            initargs=(os.getpid(), context),
        )

    def start(self, context: worker.Context | None = None) -> None:
        """Spawn the workers now: they start (import planbench, MuJoCo and the scenario's
        mechanism of ``context``) while the driver checks the runs and opens its
        directory; ``run`` uses them. ``close`` ends them if ``run`` never does. Submitting
        spawns a worker per task until the pool is full, with SIGINT, SIGTERM and SIGHUP
        held back (as ``run``'s submits)."""
        if self._pool is not None:
            return
        self._pool = self._new_pool(context)
        with outputs.signals_deferred():
            for _ in range(self.workers):
                try:
                    self._pool.submit(_warm)
                except cf.process.BrokenProcessPool:  # run() finds it broken and starts another
                    break

    def close(self) -> None:
        """End the started pool that ``run`` did not take (the campaign stopped before it),
        or the kept one."""
        pool, self._pool = self._pool, None
        if pool is not None:
            _terminate(pool)

    def run(self, context, chunks):
        """Yield (chunk, result) as chunks finish, with at most two chunks per worker in
        flight (``chunks`` may be a generator). A worker that dies (out of memory, a crash in
        native code) takes its pool with it: the chunks in flight are tried once more, one at
        a time, in a new pool, and one that breaks a pool again is given error rows; the rest
        go on. A kept pool (``with``) stays up for the next campaign; an interrupt ends it."""
        source = iter(chunks)
        retry = collections.deque()
        broke_once = set()

        def next_chunks(n):
            out = []
            while len(out) < n:
                if retry:
                    out.append(retry.popleft())
                    continue
                chunk = next(source, None)
                if chunk is None:
                    break
                out.append(chunk)
            return out

        while True:
            # The pool ``start`` spawned (or a kept one), or a new one (none was started, or one broke).
            pool, self._pool = (self._pool or self._new_pool(context)), None
            broken, unsent = [], []
            futures = {}

            def submit(batch, pool=pool, futures=futures, unsent=unsent):  # (this round's pool)
                # A pool can break between two submits (a worker died meanwhile); a chunk it
                # refuses never ran, so it goes back to the queue without counting as a death.
                # Submitting spawns workers: with SIGINT, SIGTERM and SIGHUP held back, an
                # interrupt never cuts a spawn (or its semaphores) in half, and each worker
                # starts with them blocked until contain_worker has set them.
                with outputs.signals_deferred():
                    for i, c in enumerate(batch):
                        try:
                            futures[pool.submit(_run_in_worker, context, c)] = c
                        except cf.process.BrokenProcessPool:
                            unsent.extend(batch[i:])
                            return

            try:
                # Chunks that were in flight when a pool broke run one at a time, so the one
                # that breaks it again is known; the others go on as usual.
                submit(next_chunks(1 if retry else 2 * self.workers))
                while futures:
                    done, _ = cf.wait(futures, return_when=cf.FIRST_COMPLETED)
                    for future in done:
                        chunk = futures.pop(future)
                        try:
                            result = future.result()
                        except cf.process.BrokenProcessPool:
                            broken.append(chunk)
                            continue
                        except Exception as e:  # noqa: BLE001  (pickling, a worker's import error)
                            result = _lost(context, chunk, worker._exception_text(e))
                        yield chunk, result
                    if not broken and not unsent:
                        submit(next_chunks((1 if retry else 2 * self.workers) - len(futures)))
            except BaseException:
                _terminate(pool)
                raise
            if not broken and not unsent:
                if self.kept:
                    self._pool = pool
                else:
                    pool.shutdown(wait=True)
                return
            pool.shutdown(wait=True)
            retry.extendleft(reversed(unsent))
            for chunk in sorted(broken, key=_first_run, reverse=True):
                if _first_run(chunk) in broke_once:
                    yield (
                        chunk,
                        _lost(
                            context,
                            chunk,
                            "its worker process died twice running it (out of memory, or a crash in native code)",
                        ),
                    )
                else:
                    broke_once.add(_first_run(chunk))
                    retry.appendleft(chunk)


def _first_run(chunk) -> int:
    """The index of a chunk's first run (a list of RunTasks, or a ColumnTask)."""
    if isinstance(chunk, worker.ColumnTask):
        return int(chunk.columns["run"][0])
    return chunk[0].index


def _terminate(pool) -> None:
    """End a pool now (an interrupt, an error): its workers get SIGTERM, then SIGKILL, and
    the pool's manager thread is waited for. That thread closes the pool's wake-up pipe when
    it sees the workers gone; were it still running at interpreter exit, concurrent.futures'
    exit hook could write to that pipe as it closes and print a traceback after planbench's
    one-line error (CPython 3.11)."""
    with outputs.signals_deferred():
        processes = list((getattr(pool, "_processes", None) or {}).values())
        manager = getattr(pool, "_executor_manager_thread", None)  # shutdown() forgets it
        pool.shutdown(wait=False, cancel_futures=True)
        for p in processes:
            if p.is_alive():
                p.terminate()
        for p in processes:
            p.join(timeout=5)
            if p.is_alive():
                p.kill()
                p.join(timeout=5)
        if manager is not None:
            manager.join(timeout=5)


class RayEngine:
    """Ray tasks on the cluster at ``address`` (or RAY_ADDRESS), or on a local instance of
    ``workers`` CPUs. A Ray instance that is already initialized (``ray.init`` by the caller)
    is used as it is and left running."""

    name = "ray"

    def __init__(self, address: str | None = None, workers: int | None = None):
        self.address, self.workers = address, workers

    def run(self, context, chunks):
        import ray

        started = False
        if not ray.is_initialized():
            address = self.address or os.environ.get("RAY_ADDRESS")
            options = dict(include_dashboard=False, log_to_driver=False, configure_logging=False)
            if address:
                _ray_connect(ray, address, options)
            else:
                ray.init(num_cpus=self.workers or os.cpu_count() or 1, **options)
            started = True
        try:
            # One BLAS thread, as in every planbench process (sims/__init__.py): the same
            # numbers as the local engine's, bit for bit.
            threads = {
                v: os.environ.get(v, "1") for v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
            }
            remote = ray.remote(num_cpus=1, max_retries=0, runtime_env={"env_vars": threads})(worker.run_chunk)
            context_ref = ray.put(context)
            source = iter(chunks)
            in_flight = 2 * int(ray.cluster_resources().get("CPU", 1))
            pending = {remote.remote(context_ref, chunk): chunk for chunk in itertools.islice(source, in_flight)}
            try:
                while pending:
                    done, _ = ray.wait(list(pending), num_returns=1, timeout=1.0)
                    for ref in done:
                        chunk = pending.pop(ref)
                        try:
                            result = ray.get(ref)
                        except Exception as e:  # noqa: BLE001  (a worker lost, a task error)
                            result = _lost(context, chunk, worker._exception_text(e))
                        yield chunk, result
                    for chunk in itertools.islice(source, in_flight - len(pending)):
                        pending[remote.remote(context_ref, chunk)] = chunk
            except BaseException:
                for ref in pending:
                    ray.cancel(ref, force=True)
                raise
        finally:
            if started:
                ray.shutdown()


#: How long ``--engine ray --address HOST:PORT`` waits for the cluster's GCS port to accept a
#: connection before the campaign is refused (s); ray.init itself would retry for ever.
RAY_CONNECT_TIMEOUT_S = 30.0


def _check_reachable(address: str, timeout: float | None = None) -> None:
    """ParamError unless a TCP connection to the Ray cluster at ``address`` (HOST:PORT, the
    GCS) opens within ``timeout`` s (RAY_CONNECT_TIMEOUT_S). "auto", "local" and ray://
    addresses are left to Ray."""
    import socket

    from planbench.params import ParamError

    timeout = RAY_CONNECT_TIMEOUT_S if timeout is None else timeout
    if address in ("auto", "local") or "://" in address:
        return
    host, sep, port = address.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ParamError(f"--address {address!r} is not HOST:PORT of a Ray cluster's head")
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout):
            return
    except ConnectionRefusedError:  # a definite answer: nothing listens there
        raise ParamError(
            f"--address {address}: nothing listens there (connection refused); start the "
            "cluster (ray start --head) or check the address"
        ) from None
    except OSError as e:  # a timeout, an unknown host, no route
        raise ParamError(
            f"--address {address}: no Ray cluster answered within {timeout:g} s "
            f"({e.strerror or e or 'timed out'}); start it (ray start --head) or check the "
            "address"
        ) from None


def _ray_connect(ray, address: str, options: dict) -> None:
    """``ray.init(address=...)`` with Ray's log lines on stderr held back (its GCS client
    writes one per retry); a failure is a ParamError: one error line. Ray's client gives up
    by itself (about 20 s with Ray 2.x when a port answers that is not a Ray head)."""
    import tempfile

    from planbench.params import ParamError

    saved = os.dup(2)
    try:
        with tempfile.TemporaryFile() as log:
            os.dup2(log.fileno(), 2)
            try:
                ray.init(address=address, **options)
            except Exception as e:  # noqa: BLE001  (ConnectionError, RuntimeError: Ray's own)
                raise ParamError(
                    f"--address {address}: no Ray cluster there ({type(e).__name__}: "
                    f"{str(e).splitlines()[0] if str(e) else 'no reason given'})"
                ) from None
            finally:
                os.dup2(saved, 2)
    finally:
        os.close(saved)


def ray_available() -> bool:
    import importlib.util

    return importlib.util.find_spec("ray") is not None


def make(engine, workers: int | None, address: str | None):
    """The engine called ``engine`` ("local", "ray") with ``workers`` and ``address``, or
    ``engine`` itself when it is one (a pool or Ray engine the caller holds)."""
    from planbench.params import ParamError

    if isinstance(engine, (LocalEngine, RayEngine)):
        if workers is not None or address is not None:
            raise ParamError("workers and address are the engine's own when an engine is given")
        return engine
    if engine not in ENGINES:
        raise ParamError(f"--engine {engine!r} is not one of {', '.join(ENGINES)}")
    if workers is not None and not 1 <= workers <= 4096:
        raise ParamError(f"--workers {workers} is outside [1, 4096]")
    if engine == "local":
        if address:
            raise ParamError("--address is for --engine ray")
        return LocalEngine(workers)
    if not ray_available():
        raise ParamError("--engine ray needs Ray: pip install 'planbench[ray]'")
    if address or os.environ.get("RAY_ADDRESS"):
        _check_reachable(address or os.environ["RAY_ADDRESS"])  # before anything is written
    return RayEngine(address, workers)
