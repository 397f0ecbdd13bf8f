"""``facsim studio`` on the command line: one-line errors, and a token when not on loopback."""
from __future__ import annotations

import json
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request

import pytest

pytest.importorskip("fastapi")

STUDIO = [sys.executable, "-m", "facsim.studio"]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_bad_port_is_one_line():
    done = subprocess.run([*STUDIO, "--port", "99999"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and "port must be" in done.stderr and "Traceback" not in done.stderr


def test_busy_port_is_one_line():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        done = subprocess.run([*STUDIO, "--port", str(port)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and f"cannot listen on 127.0.0.1:{port}" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_other_host_prints_and_requires_a_token():
    port = free_port()
    proc = subprocess.Popen([*STUDIO, "--host", "0.0.0.0", "--port", str(port)], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    try:
        line = proc.stdout.readline()
        assert "?token=" in line, line
        token = line.strip().rsplit("?token=", 1)[1]
        url = f"http://127.0.0.1:{port}/api/health"
        for _ in range(150):
            try:
                urllib.request.urlopen(url, timeout=2)
            except urllib.error.HTTPError as exc:
                assert exc.code == 401 and "token" in json.loads(exc.read())["error"]
                break
            except OSError:
                time.sleep(0.2)
        else:
            raise AssertionError("the studio did not answer")
        request = urllib.request.Request(url, headers={"X-Facsim-Token": token})
        assert json.loads(urllib.request.urlopen(request, timeout=10).read())["ok"] is True
    finally:
        proc.terminate()
        proc.wait(timeout=30)
