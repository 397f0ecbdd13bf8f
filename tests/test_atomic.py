"""Atomic writes: the old file survives a failed write; permissions are the usual ones."""
from __future__ import annotations

import os

import pytest

from facsim.atomic import atomic_write, commit, temp_beside


def test_failed_write_keeps_the_old_file(tmp_path):
    path = tmp_path / "t.yaml"
    path.write_text("old")

    def fail(tmp):
        tmp.write_text("half")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError):
        atomic_write(path, fail)
    assert path.read_text() == "old" and [p.name for p in tmp_path.iterdir()] == ["t.yaml"]


def test_new_files_get_umask_permissions(tmp_path):
    mask = os.umask(0o022)
    try:
        out = atomic_write(tmp_path / "a.txt", lambda tmp: tmp.write_text("x"))
    finally:
        os.umask(mask)
    assert out.stat().st_mode & 0o777 == 0o644


def test_folders_replace_the_old_folder(tmp_path):
    target = tmp_path / "frames"
    target.mkdir()
    (target / "stale.png").write_text("old")
    tmp = temp_beside(target, directory=True)
    (tmp / "frame_00000.png").write_text("new")
    commit(tmp, target)
    assert [p.name for p in target.iterdir()] == ["frame_00000.png"]
