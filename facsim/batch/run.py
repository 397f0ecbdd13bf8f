"""Render a stimulus set into a folder: resumable, in a process pool or on Dask.

:func:`run_batch` expands the spec, skips the files a previous run finished
(their checksums verified against the journal), renders the rest on
``workers`` processes (``spawn``: an EGL context inherited through ``fork``
hangs) or on a Dask cluster, writes each file atomically as its bytes come
back, journals it, and writes the manifest when the set is complete.

Nothing lost, nothing twice: the parent is the only writer; a file is in
the journal only once it is complete on disk; a rerun after a kill (any
signal, any moment) finishes the rest; the finished folder is byte-identical
to an uninterrupted run. A folder made from a different spec is refused
unless ``force``.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import os
import signal
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterator

import facsim
from facsim.atomic import atomic_write

from .items import Item, expand
from .manifest import STATE_DIR, Journal, read_state, sha256_file, write_manifest, write_state
from .spec import StimulusSet


class BatchError(RuntimeError):
    """A set that cannot be (or was not completely) made, in one line."""


@dataclass
class BatchResult:
    """What a run did: ``items`` in the set, ``resumed`` already done, ``rendered`` now, ``failed`` keys."""

    folder: Path
    items: int
    resumed: int
    rendered: int
    seconds: float
    failed: list[str] = field(default_factory=list)
    manifest: Path | None = None


class Progress:
    """One line on stderr: counts, rate and ETA. Redrawn in place on a terminal,
    a line per tenth of the set in a log."""

    def __init__(self, total: int, resumed: int, *, enabled: bool = True, stream=None):
        self.total, self.resumed, self.enabled = total, resumed, enabled
        self.stream = stream or sys.stderr
        self.start = time.perf_counter()
        self.live = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.step = max(1, -(-(total - resumed) // 10))
        self.done = resumed

    def text(self, now: float | None = None) -> str:
        new = self.done - self.resumed
        elapsed = max((now or time.perf_counter()) - self.start, 1e-9)
        rate = new / elapsed
        left = self.total - self.done
        eta = _clock(left / rate) if new and rate > 0 else "--:--"
        bar = "#" * int(30 * self.done / max(self.total, 1))
        resumed = f", {self.resumed} resumed" if self.resumed else ""
        return (f"facsim: batch [{bar:<30}] {self.done}/{self.total} items{resumed}, {rate:.2f} items/s, "
                f"ETA {eta}")

    def update(self, done: int) -> None:
        self.done = done
        new = done - self.resumed
        if not self.enabled or not (self.live or new % self.step == 0 or done >= self.total):
            return
        self.stream.write(("\r" if self.live else "") + self.text())
        if done >= self.total or not self.live:
            self.stream.write("\n")
        self.stream.flush()


def _clock(seconds: float) -> str:
    seconds = int(round(seconds))
    h, rest = divmod(seconds, 3600)
    return f"{h}:{rest // 60:02d}:{rest % 60:02d}" if h else f"{rest // 60}:{rest % 60:02d}"


def render_threads(workers: int, cores: int | None = None) -> int:
    """llvmpipe threads per worker so that workers × threads ≈ cores (at least 1)."""
    cores = cores or os.cpu_count() or 1
    return max(1, cores // max(1, workers))


# ----------------------------------------------------------- the folder ---

def _stray_temporaries(folder: Path) -> Iterator[Path]:
    """Half-written files facsim.atomic left behind when a run was killed ('.NAME.XXXX.partSUFFIX')."""
    for path in folder.rglob(".*.part*"):
        if path.is_file() and STATE_DIR not in path.parts[len(folder.parts):-1]:
            yield path


@contextlib.contextmanager
def _folder_lock(folder: Path):
    import fcntl

    (folder / STATE_DIR).mkdir(parents=True, exist_ok=True)
    with open(folder / STATE_DIR / "lock", "w") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise BatchError(f"another facsim batch is writing into {folder}; wait for it or stop it") from None
        yield


def _claim(folder: Path, spec: StimulusSet, items: tuple[Item, ...], journal: Journal, force: bool) -> None:
    """Check the folder belongs to this spec (or, with ``force``, take it over)."""
    state = read_state(folder)
    if state is not None and state.get("spec_hash") != spec.spec_hash:
        if not force:
            raise BatchError(f"{folder} holds a set made from a different spec (or facsim version); "
                             "use --force to replace it, or another output folder")
        wanted = {it.file for it in items}
        for entry in journal.load().values():  # the old set's files that the new one does not make
            if entry["file"] not in wanted:
                (folder / entry["file"]).unlink(missing_ok=True)
        journal.reset()
    write_state(folder, {"spec_hash": spec.spec_hash, "facsim_version": facsim.__version__,
                         "items": len(items)})


def verified(folder: Path, items: tuple[Item, ...], journal: Journal) -> dict[str, dict]:
    """Journal entries whose file is there with the recorded checksum (the rest is made again)."""
    entries = journal.load()
    done = {}
    for item in items:
        entry = entries.get(item.key)
        if entry is None or entry["file"] != item.file:
            continue
        path = folder / item.file
        if path.is_file() and path.stat().st_size == entry["bytes"] and sha256_file(path) == entry["checksum"]:
            done[item.key] = entry
    return done


#: Long items first within a character (videos, then glb, then stills), so the set does not end
#: with one worker finishing a video while the others are idle.
_KIND_ORDER = {"video": 0, "glb": 1, "still": 2}


def _locality(item: Item) -> tuple:
    """Render order: items of one character and engine together, so workers reuse their faces."""
    return (item.character, item.engine, item.width, item.height, _KIND_ORDER[item.kind], item.key)


# ------------------------------------------------------------ executors ---

#: Times a broken process pool (a worker killed or crashed) is started again for the items it lost.
POOL_RESTARTS = 2


def _local_results(todo: list[Item], workers: int, threads: int) -> Iterator[tuple[Item, bytes | BaseException]]:
    """Render on ``workers`` spawned processes; yields (item, bytes or the exception) as each finishes.

    A worker that dies (killed, out of memory, a crash in the driver) breaks the whole pool; the items
    it and the others still had are then given to a new pool, up to :data:`POOL_RESTARTS` times.
    """
    from concurrent.futures.process import BrokenProcessPool

    pending, restarts = list(todo), 0
    while pending:
        lost: list[tuple[Item, BaseException]] = []
        for item, result in _one_pool(pending, workers, threads):
            if isinstance(result, BrokenProcessPool):
                lost.append((item, result))
            else:
                yield item, result
        if lost and restarts < POOL_RESTARTS:
            restarts += 1
            pending = sorted((item for item, _ in lost), key=_locality)
            continue
        yield from lost
        return


def _one_pool(todo: list[Item], workers: int, threads: int) -> Iterator[tuple[Item, bytes | BaseException]]:
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    from .work import init_worker, render_item

    pool = ProcessPoolExecutor(max_workers=min(workers, len(todo)), initializer=init_worker, initargs=(threads,),
                               mp_context=multiprocessing.get_context("spawn"))
    finished = False
    try:
        futures = {pool.submit(render_item, item): item for item in todo}
        for future in as_completed(futures):
            item = futures.pop(future)
            try:
                yield item, future.result()
            except Exception as exc:  # noqa: BLE001 — one failed item must not stop the set
                yield item, exc
        finished = True
    finally:
        if finished:
            pool.shutdown(wait=True)
        else:  # interrupted: stop now; what the workers were doing is simply not journaled
            processes = list((getattr(pool, "_processes", None) or {}).values())
            pool.shutdown(wait=False, cancel_futures=True)
            for process in processes:
                with contextlib.suppress(Exception):
                    process.terminate()
            for process in processes:
                with contextlib.suppress(Exception):
                    process.join(5)


def _threads_by_host(client) -> dict[str, int]:
    """llvmpipe threads per worker on each host of a running cluster: its cores / its workers' threads."""
    from urllib.parse import urlparse

    cores = client.run(os.cpu_count)  # {worker address: cores of its machine}
    nthreads = client.nthreads()      # {worker address: threads of that worker}
    per_host: dict[str, list[int]] = {}
    host_cores: dict[str, int] = {}
    for address, n in nthreads.items():
        host = urlparse(address).hostname or address
        per_host.setdefault(host, []).append(int(n))
        host_cores[host] = int(cores.get(address) or 1)
    return {host: max(1, host_cores[host] // max(1, sum(n))) for host, n in per_host.items()}


def render_on_dask(item: Item, threads_by_host: dict) -> bytes:
    """The Dask task: :func:`facsim.batch.work.render_item` with this host's thread count."""
    from urllib.parse import urlparse

    from distributed import get_worker

    from .work import render_item

    host = urlparse(get_worker().address).hostname
    return render_item(item, threads_by_host.get(host, 1))


def _dask_results(todo: list[Item], *, workers: int, scheduler: str | None
                  ) -> Iterator[tuple[Item, bytes | BaseException]]:
    """Render on Dask: a LocalCluster of ``workers`` processes (1 thread each), or the cluster at ``scheduler``."""
    from distributed import Client, LocalCluster, as_completed

    cluster = None
    if scheduler is None:
        # Workers are spawned processes and inherit LP_NUM_THREADS from here, at start-up.
        with _environment(LP_NUM_THREADS=str(render_threads(workers))):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None, host="127.0.0.1")
        client = Client(cluster)
    else:
        client = Client(scheduler, timeout=30)
    try:
        if scheduler is not None:
            client.wait_for_workers(1, timeout=60)
        threads = _threads_by_host(client)
        futures = {}
        for item in todo:
            # Deterministic keys: a task resubmitted for the same item is the same task.
            key = "facsim-item-" + hashlib.sha1(item.key.encode()).hexdigest()
            futures[client.submit(render_on_dask, item, threads, key=key, pure=False, retries=3)] = item
        for future in as_completed(list(futures)):
            item = futures.pop(future)
            try:
                yield item, future.result()
            except Exception as exc:  # noqa: BLE001
                yield item, exc
            future.release()
    finally:
        with contextlib.suppress(Exception):
            client.close()
        if cluster is not None:
            with contextlib.suppress(Exception):
                cluster.close()


@contextlib.contextmanager
def _environment(**values: str):
    saved = {k: os.environ.get(k) for k in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


# ------------------------------------------------------------------ run ---

def _store(folder: Path, journal: Journal, item: Item, data: bytes) -> dict:
    """Write one finished file atomically, then journal it (in that order: a line means a whole file)."""
    path = folder / item.file
    path.parent.mkdir(parents=True, exist_ok=True)
    # overwrite: the set's folder is claimed for this spec (_claim), and a file it names that failed
    # verification (damaged, half-written by another tool) is replaced by the one the spec defines.
    atomic_write(path, lambda tmp: tmp.write_bytes(data), overwrite=True)
    journal.append(item.key, item.file, hashlib.sha256(data).hexdigest(), len(data))
    return journal.entries[item.key]


@contextlib.contextmanager
def _sigterm_as_interrupt():
    """SIGTERM stops the run like Ctrl-C (workers stopped, what is done kept)."""
    def handler(signum, frame):
        raise KeyboardInterrupt

    try:
        previous = signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not the main thread
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def run_batch(spec: StimulusSet, folder: str | os.PathLike, *, workers: int = 1, dask: bool = False,
              scheduler: str | None = None, force: bool = False, progress: bool = True,
              on_item: Callable[[Item], None] | None = None) -> BatchResult:
    """Make every file of ``spec`` in ``folder`` (see the module docstring).

    Parameters
    ----------
    workers : int
        Worker processes (process pool, or LocalCluster with ``dask``).
    dask : bool
        Start a Dask LocalCluster (processes, one thread each).
    scheduler : str, optional
        ``tcp://HOST:PORT`` of a running Dask scheduler to use instead.
    force : bool
        Replace a set made from a different spec.
    on_item : callable, optional
        Called with each item once its file is written and journaled.

    Raises
    ------
    BatchError
        Folder of another spec, a folder in use, or items that failed (the
        rest is kept; rerun to retry them).
    """
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    start = time.perf_counter()
    folder = Path(folder)
    items = expand(spec)
    folder.mkdir(parents=True, exist_ok=True)
    with _folder_lock(folder):
        journal = Journal(folder)
        _claim(folder, spec, items, journal, force)
        for stray in _stray_temporaries(folder):
            stray.unlink(missing_ok=True)
        done = verified(folder, items, journal)
        todo = sorted((it for it in items if it.key not in done), key=_locality)
        bar = Progress(len(items), len(done), enabled=progress)
        failed: list[str] = []
        first_error = None
        if todo:
            if dask or scheduler:
                results = _dask_results(todo, workers=workers, scheduler=scheduler)
            else:
                n = min(workers, len(todo))
                results = _local_results(todo, n, render_threads(n))
            count = len(done)
            try:
                with _sigterm_as_interrupt():
                    for item, result in results:
                        if isinstance(result, BaseException):
                            failed.append(item.key)
                            first_error = first_error or f"{item.key}: {result}"
                            continue
                        done[item.key] = _store(folder, journal, item, result)
                        count += 1
                        bar.update(count)
                        if on_item is not None:
                            on_item(item)
            finally:
                results.close()  # stops the workers if we leave early
                journal.close()
        else:
            bar.update(len(done))
        result = BatchResult(folder, len(items), len(items) - len(todo), len(todo) - len(failed),
                             time.perf_counter() - start, failed)
        if failed:
            raise BatchError(f"{len(failed)} of {len(items)} items failed (the others are kept; rerun to retry "
                             f"them); first: {first_error}")
        journal.entries = {k: done[k] for k in sorted(done)}
        journal.rewrite_sorted()
        paths = write_manifest(folder, items, done, spec=json.loads(spec.spec_json), spec_hash=spec.spec_hash,
                               naming=spec.naming, key_file=spec.key_file, version=facsim.__version__)
        result.manifest = paths[-1]
        return result


__all__ = ["BatchError", "BatchResult", "Progress", "render_threads", "run_batch", "verified"]
