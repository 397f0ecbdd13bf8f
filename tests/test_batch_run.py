"""Stimulus sets end to end: a process pool, a Dask LocalCluster, a real Dask cluster that loses a
worker, and a CLI run killed and resumed. Every variant must give the same bytes."""
from __future__ import annotations

import csv
import io
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from facsim.batch.items import expand
from facsim.batch.run import BatchError, run_batch
from facsim.batch.spec import load_spec

TINY = """\
name: tiny
seed: 5
characters: [ava, liam]
sizes: [40]
blocks:
  - name: au
    aus: [1, 12]
    outputs:
      stills: [50%, 100%]
      video: {onset: 0.2, apex: 0.1, offset: 0.2, fps: 10}
  - name: emo
    emotions: [happiness]
    intensities: [50%, 100%]
    outputs: {stills: [100%]}
  - name: glb
    characters: [ava]
    facs: ["6+12"]
    outputs: {glb: true}
"""
N_ITEMS = 2 * 2 * 3 + 2 * 2 + 1


def tree(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` (the run's own records included) by relative path."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file() and p.name != "lock"}


@pytest.fixture(scope="module")
def spec_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("spec") / "tiny.yaml"
    path.write_text(TINY)
    return path


@pytest.fixture(scope="module")
def reference(spec_file, tmp_path_factory) -> dict[str, bytes]:
    """The tiny set made once, uninterrupted, in a pool of two spawned processes."""
    folder = tmp_path_factory.mktemp("pool")
    result = run_batch(load_spec(spec_file), folder, workers=2, progress=False)
    assert (result.items, result.rendered, result.resumed) == (N_ITEMS, N_ITEMS, 0)
    return tree(folder)


def manifest_rows(files: dict[str, bytes]) -> list[dict]:
    return list(csv.DictReader(io.StringIO(files["manifest.csv"].decode())))


def test_pool_makes_every_file_and_the_manifest_says_what_each_shows(spec_file, reference):
    items = expand(load_spec(spec_file))
    rows = manifest_rows(reference)
    assert [r["file"] for r in rows] == sorted(it.file for it in items)
    for r in rows:
        data = reference[r["file"]]
        assert len(data) == int(r["file_bytes"]) and r["checksum"] == __import__("hashlib").sha256(data).hexdigest()
    by_file = {r["file"]: r for r in rows}
    still = by_file["au/liam/AU12_i050.png"]
    assert (still["kind"], still["character"], still["facs"], still["aus"], still["intensity"]) == \
        ("still", "liam", "12", "12", "0.5")
    image = np.asarray(Image.open(io.BytesIO(reference["au/liam/AU12_i050.png"])))
    assert image.shape == (40, 40, 4) and image[..., :3].std() > 10  # a face, not a blank frame
    video = by_file["au/ava/AU01_i100.mp4"]
    assert (video["duration"], video["fps"], video["onset"], video["apex"], video["offset"]) == \
        ("0.5", "10", "0.2", "0.1", "0.2")
    assert reference["glb/ava/AU6_12_i100.glb"][:4] == b"glTF"
    assert by_file["emo/ava/happiness_i050.png"]["emotion"] == "happiness"
    import json

    document = json.loads(reference["manifest.json"])
    assert document["spec"]["name"] == "tiny" and document["facsim_version"] and len(document["rows"]) == N_ITEMS


def test_video_has_every_frame(reference, tmp_path):
    import imageio_ffmpeg

    path = tmp_path / "v.mp4"
    path.write_bytes(reference["au/ava/AU01_i100.mp4"])
    frames, _ = imageio_ffmpeg.count_frames_and_secs(str(path))
    assert frames == 5  # 0.5 s at 10 fps


def test_rerun_resumes_verified_files_and_redoes_damaged_ones(spec_file, reference, tmp_path):
    folder = tmp_path / "set"
    for name, data in reference.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(data)
    spec = load_spec(spec_file)
    result = run_batch(spec, folder, workers=1, progress=False)
    assert (result.resumed, result.rendered) == (N_ITEMS, 0)
    (folder / "au/ava/AU12_i100.png").write_bytes(b"not a png")       # damaged
    (folder / "emo/liam/happiness_i100.png").unlink()                   # lost
    (folder / "au/ava/.AU01_i050.png.x1y2.part.png").write_bytes(b"")   # left by a killed writer
    (folder / "manifest.csv").unlink()
    result = run_batch(spec, folder, workers=1, progress=False)
    assert (result.resumed, result.rendered) == (N_ITEMS - 2, 2)
    assert tree(folder) == reference


def test_a_changed_spec_is_refused_unless_forced(spec_file, reference, tmp_path):
    folder = tmp_path / "set"
    for name, data in reference.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(data)
    changed = tmp_path / "changed.yaml"
    changed.write_text(TINY.replace("aus: [1, 12]", "aus: [12]"))
    with pytest.raises(BatchError, match="different spec"):
        run_batch(load_spec(changed), folder, progress=False)
    assert tree(folder) == reference  # nothing touched
    result = run_batch(load_spec(changed), folder, workers=1, progress=False, force=True)
    assert result.items == N_ITEMS - 6 and result.rendered == result.items  # journal dropped: all made again
    assert not (folder / "au/ava/AU01_i100.mp4").exists()  # the old set's files are gone
    assert (folder / "au/ava/AU12_i100.mp4").read_bytes() == reference["au/ava/AU12_i100.mp4"]


def test_dask_local_cluster_gives_the_same_bytes(spec_file, reference, tmp_path):
    pytest.importorskip("distributed")
    result = run_batch(load_spec(spec_file), tmp_path, workers=2, dask=True, progress=False)
    assert result.rendered == N_ITEMS
    assert tree(tmp_path) == reference


def _start(args: list[str], log: Path) -> subprocess.Popen:
    env = {**os.environ, "DASK_DISTRIBUTED__WORKER__DAEMON": "False"}
    return subprocess.Popen(args, stdout=log.open("wb"), stderr=subprocess.STDOUT, env=env,
                            start_new_session=True)


def _stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGTERM)
        try:
            process.wait(10)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait(10)


def test_real_cluster_loses_a_worker_and_still_completes_the_set(spec_file, reference, tmp_path):
    """A `dask scheduler` and two `dask worker` processes on loopback; one is killed (SIGKILL) mid-run."""
    pytest.importorskip("distributed")
    from distributed import Client

    dask = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
    worker = [sys.executable, "-m", "distributed.cli.dask_worker"]
    scheduler_file = tmp_path / "scheduler.json"
    processes = [_start([*dask, "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                         "--scheduler-file", str(scheduler_file)], tmp_path / "scheduler.log")]
    try:
        deadline = time.monotonic() + 60
        while not scheduler_file.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        for i in range(2):  # no nanny: a killed worker stays dead, its tasks must move
            processes.append(_start([*worker, "--scheduler-file", str(scheduler_file), "--nthreads", "1",
                                     "--no-nanny", "--host", "127.0.0.1", "--no-dashboard", "--name", f"w{i}"],
                                    tmp_path / f"worker{i}.log"))
        import json

        address = json.loads(scheduler_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        monitor = Client(address, timeout=30)
        monitor.wait_for_workers(2, timeout=60)
        names = {addr: info["name"] for addr, info in monitor.scheduler_info()["workers"].items()}
        killed = []

        def kill_a_busy_worker(item):
            """After the first file: SIGKILL a worker that is rendering an item right now."""
            if killed:
                return
            busy = {addr: keys for addr, keys in monitor.processing().items() if keys}
            addr = sorted(busy)[0]
            victim = processes[1 + int(names[addr][1:])]
            os.kill(victim.pid, signal.SIGKILL)
            killed.append((victim, busy[addr]))

        try:
            result = run_batch(load_spec(spec_file), tmp_path / "set", scheduler=address, progress=False,
                               on_item=kill_a_busy_worker)
            assert len(monitor.scheduler_info()["workers"]) == 1
        finally:
            monitor.close()
        victim, lost = killed[0]
        assert victim.wait(10) == -signal.SIGKILL and lost  # it died with work in hand
        assert result.rendered == N_ITEMS
        assert tree(tmp_path / "set") == reference
    finally:
        for process in reversed(processes):
            _stop(process)


def _children(pid: int) -> list[int]:
    tasks = Path(f"/proc/{pid}/task")
    return sorted({int(c) for t in tasks.iterdir() for c in (t / "children").read_text().split()})


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state not in ("Z", "X")  # a zombie has exited (pid 1 may not reap it here)


def _facsim(*args) -> list[str]:
    return [sys.executable, "-m", "facsim", *args]


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM], ids=["SIGKILL", "SIGTERM"])
def test_cli_killed_mid_run_then_rerun_gives_the_uninterrupted_bytes(spec_file, reference, tmp_path, sig):
    folder = tmp_path / "set"
    journal = folder / ".facsim-batch" / "journal.jsonl"
    run = subprocess.Popen(_facsim("batch", str(spec_file), "-o", str(folder), "--workers", "2"),
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and run.poll() is None:
        if journal.exists() and journal.read_bytes().count(b"\n") >= 3:
            break
        time.sleep(0.05)
    assert run.poll() is None, "the run ended before it could be killed"
    workers = _children(run.pid)
    assert workers, "no worker processes"
    run.send_signal(sig)
    _, err = run.communicate(timeout=60)
    deadline = time.monotonic() + 15
    while any(_alive(pid) for pid in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(_alive(pid) for pid in workers), "workers outlived the killed run"
    done = journal.read_bytes().count(b"\n")
    assert 3 <= done < N_ITEMS and not (folder / "manifest.csv").exists()
    if sig == signal.SIGTERM:
        assert run.returncode == 130 and b"rerun the same command" in err
    rerun = subprocess.run(_facsim("batch", str(spec_file), "-o", str(folder), "--workers", "2", "-q"),
                           capture_output=True, text=True, timeout=300)
    assert rerun.returncode == 0, rerun.stderr
    assert f"{N_ITEMS} files" in rerun.stdout and "already done" in rerun.stdout
    assert tree(folder) == reference


def test_cli_errors_are_one_line(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("blocks:\n  - name: a\n    aus: [3]\n    outputs: {stills: [1]}\n")
    run = subprocess.run(_facsim("batch", str(bad), "-o", str(tmp_path / "out")), capture_output=True, text=True)
    assert run.returncode == 2
    assert run.stderr.strip().splitlines() == [f"facsim: error: {bad}:3: blocks[0].aus[0]: unknown action unit 3: "
                                               "FACS defines no AU3; known codes are 1-2, 4-46, 50-58, 61-66, "
                                               "70-74, 80-82, 84-85, 91-92, 97-98"]
    assert not (tmp_path / "out").exists()


def test_timeline_and_muscle_items_render_in_process(tmp_path):
    """The worker function itself, on the two kinds the tiny set leaves out."""
    import imageio_ffmpeg

    from facsim.batch.spec import spec_from_dict
    from facsim.batch.work import render_item

    (tmp_path / "nod.yaml").write_text("fps: 10\ntracks:\n  - au: 12\n    start: 0\n    onset: 0.2\n    apex: 0.1\n"
                                       "    offset: 0.2\n")
    spec = spec_from_dict({"characters": ["zola"], "sizes": [40], "engines": ["registers", "muscle"], "blocks": [
        {"name": "t", "timelines": ["nod.yaml"], "engines": ["registers"], "outputs": {"video": True}},
        {"name": "m", "facs": ["4+6"], "outputs": {"stills": [1]}}]}, base_dir=tmp_path)
    items = {it.key: it for it in expand(spec)}
    video = tmp_path / "nod.mp4"
    video.write_bytes(render_item(items["t/zola/nod.mp4"]))
    assert imageio_ffmpeg.count_frames_and_secs(str(video))[0] == 5
    muscle = render_item(items["m/zola/AU4_6_i100_muscle.png"])
    registers = render_item(items["m/zola/AU4_6_i100_registers.png"])
    assert muscle[:8] == registers[:8] == b"\x89PNG\r\n\x1a\n" and muscle != registers


def test_a_set_without_a_body_renders_no_shoulders():
    from facsim.batch.spec import spec_from_dict
    from facsim.batch.work import render_item

    bottom = {}
    for body in ("crewneck", "none"):
        spec = spec_from_dict({"characters": ["liam"], "sizes": [64], "body": body, "blocks": [
            {"name": "b", "facs": ["0"], "outputs": {"stills": [1]}}]})
        image = np.asarray(Image.open(io.BytesIO(render_item(expand(spec)[0]))).convert("RGB")).astype(int)
        bottom[body] = float((np.abs(image[-1] - 255).max(axis=-1) > 10).mean())   # not the white background
    # The crewneck's shoulders fill the bottom row; without a body only the neck reaches it.
    assert bottom["crewneck"] > 0.9
    assert bottom["none"] < 0.7


def test_pool_worker_killed_mid_run_is_replaced_and_the_set_completes(spec_file, reference, tmp_path):
    killed = []

    def kill_a_worker(item):
        if not killed:
            workers = [pid for pid in _children(os.getpid()) if b"spawn_main" in Path(f"/proc/{pid}/cmdline").read_bytes()]
            os.kill(workers[0], signal.SIGKILL)
            killed.append(workers[0])

    result = run_batch(load_spec(spec_file), tmp_path, workers=2, progress=False, on_item=kill_a_worker)
    assert killed and result.rendered == N_ITEMS and not result.failed
    assert tree(tmp_path) == reference
