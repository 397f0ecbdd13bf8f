"""The command line: the main job works, and every user error is one line and exit 2."""
from __future__ import annotations

import subprocess
import sys

import pytest
from PIL import Image


def facsim(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "facsim.cli", *args], capture_output=True, text=True, cwd=cwd)


def test_render_writes_the_png(tmp_path):
    out = tmp_path / "surprise.png"
    r = facsim("render", "1+2+5B+26", "-o", str(out), "--character", "noah", "--view", "three-quarter-left",
               "--size", "128")
    assert r.returncode == 0, r.stderr
    assert Image.open(out).size == (128, 128)


def test_characters_lists_presets():
    r = facsim("characters")
    assert r.returncode == 0 and "kwame" in r.stdout and "african" in r.stdout.replace("afr", "african")


def test_aus_and_emotions_list_their_tables():
    r = facsim("aus")
    assert r.returncode == 0 and "Lip Corner Puller" in r.stdout and "registers" in r.stdout
    r = facsim("emotions")
    assert r.returncode == 0 and "happiness" in r.stdout


@pytest.mark.parametrize("args, message", [
    (["render", "1+2+AU99", "-o", "x.png"], "unknown action unit 'AU99' at position 4"),
    (["render", "12", "-o", "x.png", "--character", "nobody"], "unknown character 'nobody'"),
    (["render", "12", "-o", "x.png", "--size", "big"], "size must be N or WxH"),
    (["render", "12", "-o", "x.png", "--view", "top"], "invalid choice: 'top'"),
    (["render", "12", "-o", "x.png", "--background", "#12"], "colours are '#rrggbb'"),
    (["render", "-o", "x.png", "--emotion", "glee"], "glee"),
    (["render", "12", "-o", "x.png", "--emotion", "fear"], "not both"),
    (["render", "12", "-o", "x.png", "--time", "1"], "--time needs --timeline"),
    (["render", "12", "-o", "nodir/x.png"], "No such file or directory|does not exist"),
    (["render", "12"], "required: -o/--output"),
])
def test_errors_are_one_line_without_traceback(tmp_path, args, message):
    r = facsim(*args, cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr
    import re
    assert re.search(message, r.stderr), r.stderr
    assert not (tmp_path / "x.png").exists()
