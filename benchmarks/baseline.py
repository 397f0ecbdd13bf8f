"""Shared pieces of the before/after benchmarks: a baseline revision checked out beside
the working tree, and a timed run of a command in one of the two trees."""
from __future__ import annotations

import contextlib
import os
import resource
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@contextlib.contextmanager
def baseline_tree(rev: str, prefix: str = "bench-"):
    """Yield ``(scratch folder, tree)``: ``rev`` checked out as a detached git worktree in a
    temporary folder, removed (with the folder) afterwards."""
    tmp = Path(tempfile.mkdtemp(prefix=prefix))
    tree = tmp / "before"
    subprocess.run(["git", "worktree", "add", "--detach", str(tree), rev], cwd=ROOT, check=True, capture_output=True)
    try:
        yield tmp, tree
    finally:
        subprocess.run(["git", "worktree", "remove", "--force", str(tree)], cwd=ROOT, capture_output=True)
        shutil.rmtree(tmp, ignore_errors=True)


def timed(command: list[str], tree: Path, env: dict | None = None, nice: int = 0) -> tuple[float, float]:
    """(wall seconds, CPU seconds of the command and every process it waited for: user + system),
    with ``tree`` first on the Python path."""
    env = dict(os.environ, PYTHONPATH=str(tree), **(env or {}))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, cwd=tree, env=env, check=True, capture_output=True,
                   preexec_fn=(lambda: os.nice(nice)) if nice else None)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
