"""Atomic writes: the old file survives a failed write; permissions are the usual ones."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from facsim.atomic import OutputError, atomic_write, commit, overwriting, temp_beside


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


def test_a_folder_of_facsims_frames_is_replaced_only_with_overwrite(tmp_path):
    target = tmp_path / "frames"
    target.mkdir()
    (target / "frame_00007.png").write_text("old")
    with pytest.raises(OutputError, match="already holds 1 frames; use --overwrite"):
        temp_beside(target, directory=True)
    tmp = temp_beside(target, directory=True, overwrite=True)
    (tmp / "frame_00000.png").write_text("new")
    with overwriting():
        commit(tmp, target)
    assert [p.name for p in target.iterdir()] == ["frame_00000.png"]
    assert [p.name for p in tmp_path.iterdir()] == ["frames"]


@pytest.mark.parametrize("overwrite", [False, True])
def test_a_folder_holding_other_files_is_never_replaced(tmp_path, overwrite):
    target = tmp_path / "shots"
    target.mkdir()
    (target / "a.jpg").write_text("x")
    (target / "frame_00000.png").write_text("x")
    with pytest.raises(OutputError, match=r"shots is a folder holding files facsim did not write \(a\.jpg\)"):
        temp_beside(target, directory=True, overwrite=overwrite)
    assert sorted(p.name for p in target.iterdir()) == ["a.jpg", "frame_00000.png"]


def test_the_current_folder_and_its_parents_are_refused(tmp_path, monkeypatch):
    (tmp_path / "keep.txt").write_text("x")
    monkeypatch.chdir(tmp_path)
    for target in (".", "..", str(tmp_path)):
        with pytest.raises(OutputError, match="current folder"):
            temp_beside(target, directory=True, overwrite=True)
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]


def test_a_file_of_another_kind_needs_overwrite(tmp_path):
    notes = tmp_path / "notes.png"
    notes.write_text("my notes, not a picture")
    with pytest.raises(OutputError, match="not a .png file facsim would write; use --overwrite"):
        atomic_write(notes, lambda tmp: tmp.write_bytes(b"\x89PNG\r\n\x1a\n"))
    assert notes.read_text() == "my notes, not a picture"
    atomic_write(notes, lambda tmp: tmp.write_bytes(b"\x89PNG\r\n\x1a\n new"), overwrite=True)
    atomic_write(notes, lambda tmp: tmp.write_bytes(b"\x89PNG\r\n\x1a\n newer"))  # same kind: replaced
    assert notes.read_bytes().endswith(b"newer")


def test_files_and_folders_never_replace_each_other(tmp_path):
    (tmp_path / "frames").write_text("a file")
    (tmp_path / "x.yaml").mkdir()
    with pytest.raises(OutputError, match="is a file, not a folder of frames"):
        temp_beside(tmp_path / "frames", directory=True, overwrite=True)
    with pytest.raises(OutputError, match="x.yaml is a folder; name a file"):
        atomic_write(tmp_path / "x.yaml", lambda tmp: tmp.write_text("a: 1"), overwrite=True)
    assert (tmp_path / "frames").read_text() == "a file" and (tmp_path / "x.yaml").is_dir()


def test_stale_temporaries_of_killed_runs_are_removed_by_the_next_write(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True, check=True).stdout.strip()
    stale_file = tmp_path / f".clip.mp4.{dead}.abc123.part.mp4"
    stale_dir = tmp_path / f".frames.{dead}.abc123.part"
    alive_file = tmp_path / f".clip.mp4.{os.getppid()}.abc123.part.mp4"   # a run still going: kept
    stale_file.write_text("half")
    alive_file.write_text("half")
    stale_dir.mkdir()
    (stale_dir / "frame_00000.png").write_text("half")
    atomic_write(tmp_path / "clip.mp4", lambda tmp: tmp.write_bytes(b"\0\0\0\x18ftypisom"))
    tmp = temp_beside(tmp_path / "frames", directory=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["clip.mp4", alive_file.name, tmp.name])
