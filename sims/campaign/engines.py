"""Where a campaign's chunks run: a local process pool, or Ray (README, "Campaigns").

Both take the same ``Context`` and chunks of ``RunTask``s (plain data, sims.campaign.worker)
and yield each chunk's result as it finishes, in any order; the campaign writes the rows.

``LocalEngine`` is a ``concurrent.futures.ProcessPoolExecutor`` whose workers are *spawned*
(not forked): a fork would copy a parent that may hold an EGL context, MuJoCo's threads or
an open Ray connection. ``RayEngine`` submits each chunk as a Ray task (``num_cpus=1``,
no retries: a run is not repeated behind the campaign's back) to the cluster at ``address``
(or ``RAY_ADDRESS``), or to a local Ray instance it starts when neither is given.
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
import os

from sims.campaign import worker

ENGINES = ("local", "ray")


def _lost(context, chunk, why: str) -> dict:
    """Rows of a chunk whose worker died: status "error" with the reason."""
    rows = [{**worker.row_of(context, task), "status": "error", "passed": None, "error": why, "wall_s": 0.0,
             "sim_s": None} for task in chunk]
    return {"rows": rows, "checks": {}, "files": {}}


def _init_worker(context):
    worker._context = context


def _run_in_worker(chunk):
    return worker.run_chunk(worker._context, chunk)


class LocalEngine:
    """A pool of ``workers`` spawned processes (default: the machine's cores)."""

    name = "local"

    def __init__(self, workers: int | None = None):
        self.workers = workers or os.cpu_count() or 1

    def run(self, context, chunks):
        """Yield (chunk, result) as chunks finish. A worker that dies takes its pool with it:
        the unfinished chunks are tried once more in a new pool, then given error rows."""
        remaining = list(chunks)
        for attempt in range(2):
            if not remaining:
                return
            pool = cf.ProcessPoolExecutor(max_workers=min(self.workers, len(remaining)),
                                          mp_context=multiprocessing.get_context("spawn"),
                                          initializer=_init_worker, initargs=(context,))
            broken = []
            try:
                futures = {pool.submit(_run_in_worker, chunk): chunk for chunk in remaining}
                for future in cf.as_completed(futures):
                    chunk = futures[future]
                    try:
                        result = future.result()
                    except cf.process.BrokenProcessPool:
                        broken.append(chunk)
                        continue
                    except Exception as e:  # noqa: BLE001  (pickling, a worker's import error)
                        result = _lost(context, chunk, worker._exception_text(e))
                    yield chunk, result
            except BaseException:
                _terminate(pool)
                raise
            else:
                pool.shutdown(wait=True)
            remaining = sorted(broken, key=lambda c: c[0].index)
        for chunk in remaining:
            yield chunk, _lost(context, chunk, "its worker process died twice (out of memory, or a crash in native code)")


def _terminate(pool) -> None:
    processes = list(getattr(pool, "_processes", {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in processes:
        if p.is_alive():
            p.terminate()
    for p in processes:
        p.join(timeout=5)


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
                ray.init(address=address, **options)
            else:
                ray.init(num_cpus=self.workers or os.cpu_count() or 1, **options)
            started = True
        try:
            remote = ray.remote(num_cpus=1, max_retries=0)(worker.run_chunk)
            context_ref = ray.put(context)
            pending = {remote.remote(context_ref, chunk): chunk for chunk in chunks}
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
            except BaseException:
                for ref in pending:
                    ray.cancel(ref, force=True)
                raise
        finally:
            if started:
                ray.shutdown()


def ray_available() -> bool:
    import importlib.util

    return importlib.util.find_spec("ray") is not None


def make(engine: str, workers: int | None, address: str | None):
    from sims.params import ParamError

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
    return RayEngine(address, workers)
