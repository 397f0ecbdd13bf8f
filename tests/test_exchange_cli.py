"""`facsim export ...` / `facsim import ...` end to end: exit 0 and the files; user errors: one line, exit 2."""
from __future__ import annotations

import csv
import subprocess
import sys

import pytest

TIMELINE = """facsim-notation 1
fps: 10
duration: 1.2
[1+2+12+26]  0.1+0.3/0.3/0.3@0.85
AU51         0+0.4/0.2/0.4@0.6
AU12L        0.2:0>0.6:0.4~smoothstep>1:0
"""


def facsim(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "facsim", *args], capture_output=True, text=True, cwd=cwd)


@pytest.fixture()
def timeline(tmp_path):
    path = tmp_path / "clip.facs"
    path.write_text(TIMELINE)
    return path


def test_notation_exports_and_imports_losslessly(tmp_path, timeline):
    r = facsim("import", "notation", str(timeline), "-o", str(tmp_path / "clip.yaml"))
    assert r.returncode == 0, r.stderr
    r = facsim("export", "notation", str(tmp_path / "clip.yaml"), "-o", str(tmp_path / "again.facs"))
    assert r.returncode == 0, r.stderr
    from facsim.exchange import read_notation

    assert read_notation(tmp_path / "again.facs") == read_notation(timeline)
    assert facsim("export", "notation", str(timeline), "-o", "-").stdout.startswith("facsim-notation 1\n")


def test_arkit_csv_export_and_import(tmp_path, timeline):
    out = tmp_path / "take.csv"
    r = facsim("export", "arkit-csv", str(timeline), "-o", str(out))
    assert r.returncode == 0 and r.stdout.strip() == f"wrote {out}", r.stderr
    rows = list(csv.reader(out.open()))
    assert rows[0][:3] == ["Timecode", "BlendShapeCount", "EyeBlinkLeft"] and len(rows) == 13
    r = facsim("import", "arkit-csv", str(out), "-o", str(tmp_path / "back.facs"))
    assert r.returncode == 0, r.stderr
    assert "AU51" in (tmp_path / "back.facs").read_text()


def test_glb_and_mesh_exports(tmp_path, timeline):
    r = facsim("export", "glb", "-o", str(tmp_path / "ava.glb"), "--timeline", str(timeline), "--aus", "1,2,12,26",
               "--interpolation", "step", "--no-normals")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "ava.glb").read_bytes()[:4] == b"glTF"
    r = facsim("export", "mesh", "6+12", "-o", str(tmp_path / "smile.ply"), "--character", "kwame",
               "--engine", "registers")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "smile.ply").read_bytes().startswith(b"ply\n")


def test_openface_import(tmp_path):
    header = "frame, face_id, timestamp, confidence, success, AU12_r, AU45_r"
    rows = [f"{i + 1}, 0, {i / 30:.3f}, 0.98, 1, {3.0 if i >= 5 else 0.0}, 0" for i in range(15)]
    (tmp_path / "perf.csv").write_text("\n".join([header, *rows]) + "\n")
    r = facsim("import", "openface", str(tmp_path / "perf.csv"), "-o", str(tmp_path / "perf.yaml"))
    assert r.returncode == 0, r.stderr
    text = (tmp_path / "perf.yaml").read_text()
    assert "au: 12" in text and "fps: 30" in text


@pytest.mark.parametrize("args, message", [
    (["import", "notation", "{bad}", "-o", "{tmp}/x.yaml"], "bad.facs:3:6: expected a number for fps"),
    (["import", "openface", "{take}", "-o", "{tmp}/x.yaml"], "not an OpenFace CSV"),
    (["export", "glb", "-o", "{tmp}/x.glb", "--aus", "51"], "AU51 has no morph target"),
    (["export", "glb", "-o", "{tmp}/x.glb", "--aus", "one"], "--aus takes 'all' or AU codes"),
    (["export", "mesh", "6+99", "-o", "{tmp}/x.obj"], "FACS defines no AU99"),
    (["export", "arkit-csv", "{tmp}/missing.yaml", "-o", "{tmp}/x.csv"], "no such file"),
])
def test_user_errors_are_one_line_and_exit_2(tmp_path, args, message):
    (tmp_path / "bad.facs").write_text("facsim-notation 1\n\nfps: fast\n")
    (tmp_path / "take.csv").write_text("Timecode,BlendShapeCount\n00:00:00:00.000,61\n")
    paths = {"bad": tmp_path / "bad.facs", "take": tmp_path / "take.csv", "tmp": tmp_path}
    r = facsim(*[a.format(**paths) for a in args])
    assert r.returncode == 2 and message in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and r.stdout == ""
    assert not list(tmp_path.glob("x.*"))
