"""The bounded queue in front of the render worker, and the export jobs it runs.

:class:`RenderQueue` owns a one-process :class:`~concurrent.futures.ProcessPoolExecutor`
started with ``spawn`` (the worker creates its GL context itself; nothing GL
ever exists in the server process). Every piece of work goes through
:meth:`RenderQueue.submit`, which refuses work beyond ``max_pending`` with
:class:`Busy` at once instead of letting requests pile up. Jobs
(:class:`Job`) write into their own folder under the server's work folder;
progress arrives from the worker on a multiprocessing queue.
"""
from __future__ import annotations

import asyncio
import multiprocessing
import re
import shutil
import threading
import time
import uuid
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path

from . import worker

JOB_ID = re.compile(r"^[0-9a-f]{32}$")
#: Finished jobs kept (with their files) before the oldest are deleted.
MAX_JOBS_KEPT = 50


class Busy(RuntimeError):
    """The queue is full; the client should retry later (HTTP 503)."""


@dataclass
class Job:
    """One export job: its state, progress and (when done) the file it produced."""

    id: str
    kind: str
    folder: Path
    state: str = "queued"           # queued → running → done | failed | cancelled
    done: int = 0
    total: int = 0
    error: str | None = None
    filename: str | None = None
    created: float = field(default_factory=time.time)
    future: Future | None = None
    #: Every (done, total) the worker reported, in order: what the job's event stream replays.
    history: list = field(default_factory=list)

    def to_json(self) -> dict:
        return {"id": self.id, "kind": self.kind, "state": self.state, "done": self.done, "total": self.total,
                "error": self.error, "filename": self.filename,
                "download": f"/api/jobs/{self.id}/download" if self.state == "done" else None}

    @property
    def finished(self) -> bool:
        return self.state in ("done", "failed", "cancelled")


class RenderQueue:
    """The worker process and what waits for it.

    Parameters
    ----------
    workdir : path
        Jobs write into ``workdir/jobs/<id>/`` and nowhere else.
    max_pending : int
        Most tasks queued or running at once (renders, thumbnails, jobs); more get :class:`Busy`.
    """

    def __init__(self, workdir, *, max_pending: int = 8):
        self.workdir = Path(workdir)
        self.jobs_dir = self.workdir / "jobs"
        self.jobs_dir.mkdir(parents=True, exist_ok=True)
        self.max_pending = max_pending
        self.jobs: dict[str, Job] = {}
        self._lock = threading.Lock()
        self._pending = 0
        self._ctx = multiprocessing.get_context("spawn")
        self._progress = self._ctx.Queue()
        self._executor = self._new_executor()
        self._reader = threading.Thread(target=self._read_progress, name="facsim-progress", daemon=True)
        self._closed = False
        self._reader.start()
        self.served = 0
        self.refused = 0

    def _new_executor(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(max_workers=1, mp_context=self._ctx, initializer=worker.init,
                                   initargs=(self._progress,))

    # ------------------------------------------------------------ tasks ---
    @property
    def pending(self) -> int:
        return self._pending

    def submit(self, fn, *args) -> Future:
        """Queue ``fn(*args)`` for the worker, or raise :class:`Busy` when ``max_pending`` are waiting."""
        with self._lock:
            if self._closed:
                raise Busy("the studio is shutting down")
            if self._pending >= self.max_pending:
                self.refused += 1
                raise Busy(f"the render queue is full ({self._pending} waiting); try again in a moment")
            self._pending += 1
            try:
                future = self._executor.submit(fn, *args)
            except BrokenProcessPool:       # the worker died (e.g. out of memory): start a new one
                self._executor = self._new_executor()
                future = self._executor.submit(fn, *args)
            except BaseException:
                self._pending -= 1
                raise
        future.add_done_callback(self._release)
        return future

    def _release(self, future: Future) -> None:
        with self._lock:
            self._pending -= 1
            self.served += 1
            if isinstance(future.exception() if not future.cancelled() else None, BrokenProcessPool):
                self._executor = self._new_executor()

    async def run(self, fn, *args, timeout: float = 300.0):
        """Await ``fn(*args)`` in the worker (raises :class:`Busy` or the worker's exception)."""
        return await asyncio.wait_for(asyncio.wrap_future(self.submit(fn, *args)), timeout)

    # ------------------------------------------------------------- jobs ---
    def start_job(self, kind: str, spec: dict, files: dict[str, bytes] | None = None) -> Job:
        """Create a job folder (with ``files``: server-chosen name → bytes, e.g. an upload) and queue
        the job; raises :class:`Busy` when the queue is full."""
        from facsim.atomic import atomic_write

        job_id = uuid.uuid4().hex
        folder = self.jobs_dir / job_id
        folder.mkdir()
        for name, data in (files or {}).items():
            atomic_write(folder / name, lambda tmp, data=data: tmp.write_bytes(data))
        job = Job(job_id, kind, folder)
        try:
            job.future = self.submit(worker.run_job, job_id, str(folder), kind, spec)
        except Busy:
            shutil.rmtree(folder, ignore_errors=True)
            raise
        with self._lock:
            self.jobs[job_id] = job
        job.future.add_done_callback(lambda f, job=job: self._finish(job, f))
        self._prune()
        return job

    def _finish(self, job: Job, future: Future) -> None:
        if future.cancelled():
            job.state = "cancelled"
            return
        exc = future.exception()
        if exc is None:
            job.filename, job.state = future.result(), "done"
            job.done = max(job.done, job.total)
        elif isinstance(exc, worker.Cancelled):
            job.state = "cancelled"
        else:
            job.state, job.error = "failed", " ".join(str(exc).split()) or type(exc).__name__

    def job(self, job_id: str) -> Job | None:
        """The job with this id, or None (ids that are not ours are never used as paths)."""
        if not isinstance(job_id, str) or not JOB_ID.match(job_id):
            return None
        return self.jobs.get(job_id)

    def cancel(self, job: Job) -> None:
        """Stop a job: drop it if it has not started, else flag its folder for the worker's frame loop."""
        if job.finished:
            return
        if job.future is not None and job.future.cancel():
            job.state = "cancelled"
            return
        (job.folder / worker.CANCEL_FLAG).touch()

    def download_path(self, job: Job) -> Path | None:
        if job.state != "done" or not job.filename:
            return None
        path = (job.folder / job.filename).resolve()
        return path if path.parent == job.folder.resolve() and path.is_file() else None

    def _prune(self) -> None:
        with self._lock:
            finished = sorted((j for j in self.jobs.values() if j.finished), key=lambda j: j.created)
            for job in finished[:max(0, len(finished) - MAX_JOBS_KEPT)]:
                del self.jobs[job.id]
                shutil.rmtree(job.folder, ignore_errors=True)

    def _read_progress(self) -> None:
        while True:
            try:
                message = self._progress.get()
            except (EOFError, OSError, ValueError):
                return
            if message is None:
                return
            job_id, done, total = message
            job = self.jobs.get(job_id)
            if job is not None:
                job.history.append((done, total))
                if not job.finished:
                    job.state, job.done, job.total = "running", done, total

    # --------------------------------------------------------- lifetime ---
    def close(self) -> None:
        """Cancel what waits, stop the worker and the progress reader."""
        with self._lock:
            self._closed = True
        for job in list(self.jobs.values()):
            self.cancel(job)
        self._executor.shutdown(wait=True, cancel_futures=True)
        self._progress.put(None)
        self._reader.join(timeout=5)
        self._progress.close()


def default_workdir() -> Path:
    """A fresh private folder for this server's jobs."""
    import tempfile

    return Path(tempfile.mkdtemp(prefix="facsim-studio-"))

