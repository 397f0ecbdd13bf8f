"""The studio page in a real browser: Debian's chromium driven by Playwright, against a real server.

One ``facsim studio`` server (a subprocess on 127.0.0.1) and one page serve the
module; the tests run in order on that page as a user would: sliders, the FACS
field, Render, a timeline clip exported as MP4 and .glb, then a burst of 50
concurrent renders. ``FACSIM_UPDATE_DOCS=1`` also writes the page's screenshot
to docs/studio.png.
"""
from __future__ import annotations

import base64
import io
import json
import os
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("fastapi")
playwright = pytest.importorskip("playwright.sync_api")
CHROMIUM = shutil.which("chromium")
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is not installed (install.sh installs it)")
QUIET = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run"]
CLI = "import sys; from facsim.cli import main; sys.exit(main(sys.argv[1:]))"
ROOT = Path(__file__).resolve().parents[1]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def server():
    port = free_port()
    proc = subprocess.Popen([sys.executable, "-m", "facsim.studio", "--port", str(port)],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    url = f"http://127.0.0.1:{port}"
    try:
        for _ in range(300):
            if proc.poll() is not None:
                raise RuntimeError(f"facsim studio exited: {proc.stdout.read()}")
            try:
                urllib.request.urlopen(f"{url}/api/health", timeout=2)
                break
            except OSError:
                time.sleep(0.2)
        yield url, proc
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()


@pytest.fixture(scope="module")
def page(server):
    url, _ = server
    with playwright.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=QUIET)
        page = browser.new_page(viewport={"width": 1440, "height": 940})
        errors = []
        page.on("pageerror", lambda exc: errors.append(str(exc)))
        page.goto(url + "/")
        page.wait_for_function("window.studio && window.studio.ready === true", timeout=120_000)
        yield page
        assert not errors, errors
        browser.close()


def canvas(page) -> np.ndarray:
    from PIL import Image

    data = page.evaluate("() => studio.viewer.renderer.domElement.toDataURL('image/png')")
    return np.asarray(Image.open(io.BytesIO(base64.b64decode(data.split(",", 1)[1]))).convert("RGB"), np.int16)


def slider_value(page, selector) -> int:
    return int(page.eval_on_selector(selector, "e => e.value"))


def test_moving_the_au12_slider_changes_the_face(page):
    before = canvas(page)
    page.locator("#au-12").scroll_into_view_if_needed()
    box = page.locator("#au-12").bounding_box()
    page.mouse.click(box["x"] + box["width"] * 0.9, box["y"] + box["height"] / 2)    # drag-free click at 90 %
    after = canvas(page)
    changed = np.abs(after - before).sum(axis=2) > 24
    assert changed.sum() > 300, "the 3-D view did not change"
    rows = np.flatnonzero(changed.any(axis=1))
    assert rows.mean() > before.shape[0] * 0.45          # the mouth moved, in the lower half of the view
    page.wait_for_function("document.querySelector('#facs').value.startsWith('12')")
    assert 850 <= slider_value(page, "#au-12") <= 950


def test_the_3d_view_shows_the_garment_only_with_a_body(page):
    # The preview's .glb always carries the neck, shoulders and garment; with Body "none" the
    # render is the head alone, and the 3-D view showed the garment anyway.
    shown = "() => studio.viewer.root.getObjectByName('body').visible"
    assert page.eval_on_selector("#body", "e => e.value") == "crewneck" and page.evaluate(shown)
    dressed = canvas(page)
    page.select_option("#body", "none")
    assert not page.evaluate(shown)
    bare = canvas(page)
    changed = np.abs(bare - dressed).sum(axis=2) > 24
    assert changed.sum() > 300, "the garment did not go"
    assert np.flatnonzero(changed.any(axis=1)).mean() > dressed.shape[0] * 0.5   # below the face
    page.select_option("#body", "crewneck")
    assert page.evaluate(shown)
    assert (np.abs(canvas(page) - dressed).sum(axis=2) > 24).sum() < 50


def test_typing_facs_moves_the_sliders_and_errors_point_at_the_token(page):
    page.fill("#facs", "R12C+14A")
    page.wait_for_function("document.querySelector('#au-12-right').value === '550'")
    assert slider_value(page, "#au-12-left") == 0 and slider_value(page, "#au-14") == 150
    assert page.is_visible("#au-12-right") and not page.is_visible("#facs-error")
    page.fill("#facs", "1+2+AU99")
    page.wait_for_selector("#facs-error:not([hidden])")
    assert page.get_attribute("#facs-error", "data-position") == "4"
    assert page.inner_text("#facs-error mark") == "AU99"
    assert slider_value(page, "#au-12-right") == 550     # a bad string leaves the face as it was
    page.click("#reset")
    page.wait_for_function("document.querySelector('#au-12').value === '0'")


def test_render_returns_the_cli_bytes(page, tmp_path):
    page.click("button[data-tab=character]")
    page.click("button[data-character=kwame]")
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('kwame')", timeout=120_000)
    page.click("button[data-tab=expression]")
    page.select_option("#emotion-table", "emfacs")
    page.click("button[data-emotion=surprise]")
    page.wait_for_function("document.querySelector('#facs').value === '1+2+5B+26'")
    page.fill("#size", "96")
    page.select_option("#view", "three-quarter-left")
    page.select_option("#antialias", "2")
    page.select_option("#background", "grey")
    assert page.eval_on_selector("#body", "e => e.value") == "crewneck"
    page.select_option("#body", "none")
    page.click("#render")
    page.wait_for_function("document.querySelector('#render').textContent === 'Render' && "
                           "!document.querySelector('#render-figure').hidden", timeout=120_000)
    served = bytes(page.evaluate("async () => Array.from(new Uint8Array(await (await fetch("
                                 "document.querySelector('#render-image').src)).arrayBuffer()))"))
    out = tmp_path / "cli.png"
    subprocess.run([sys.executable, "-c", CLI, "render", "1+2+5B+26", "-c", "kwame", "--size", "96", "--view",
                    "three-quarter-left", "--antialias", "2", "--background", "grey", "--body", "none", "-o", str(out)],
                   check=True, capture_output=True)
    assert served == out.read_bytes()


def _download(url: str) -> bytes:
    with urllib.request.urlopen(url, timeout=60) as response:
        return response.read()


def test_timeline_clip_exports_mp4_with_progress_and_glb(page, server, tmp_path):
    url, _ = server
    page.click("#add-expression")                    # 1+2+5B+26 → four clips, 1 s onset, apex, offset
    doc = page.evaluate("() => studio.editor.doc")
    assert doc["duration"] == 3 and len(doc["tracks"]) == 4
    assert all((t["onset"], t["apex"], t["offset"]) == (1, 1, 1) for t in doc["tracks"])
    # drag the first lane's apex end from 2 s to 2.5 s: a longer apex, a shorter offset
    x0, x1, y = page.evaluate("""() => { const e = studio.editor, h = e.hits[0];
        const top = h.bottom - h.clip.intensity * h.span, r = e.canvas.getBoundingClientRect();
        return [r.left + e.x(2), r.left + e.x(2.5), r.top + top]; }""")
    page.mouse.move(x0, y)
    page.mouse.down()
    page.mouse.move(x1, y, steps=5)
    page.mouse.up()
    lane0 = page.evaluate("() => studio.editor.doc.tracks[studio.editor.hits[0].i]")
    assert (lane0["apex"], lane0["offset"]) == (1.5, 0.5)
    # scrub to the apex: the 3-D view shows the timeline
    page.evaluate("() => studio.editor.seek(1.5)")
    page.wait_for_function("studio.mode === 'timeline'")
    page.fill("#size", "64")
    page.click("button[data-export=video][data-format=mp4]")
    page.click("button[data-export=glb]")
    page.wait_for_selector("li[data-kind=video][data-state^=done]", timeout=300_000)
    page.wait_for_selector("li[data-kind=glb][data-state^=done]", timeout=300_000)
    item = page.locator("li[data-kind=video]").first
    assert int(item.get_attribute("data-progress")) >= 3       # progress events arrived while it ran
    mp4 = _download(url + item.locator("a.download").get_attribute("href"))
    assert mp4[4:8] == b"ftyp"
    (tmp_path / "clip.mp4").write_bytes(mp4)
    import imageio_ffmpeg

    frames, seconds = imageio_ffmpeg.count_frames_and_secs(str(tmp_path / "clip.mp4"))
    assert frames == 90 and seconds == pytest.approx(3.0, abs=0.05)
    glb = _download(url + page.locator("li[data-kind=glb] a.download").get_attribute("href"))
    document = json.loads(glb[20:20 + int.from_bytes(glb[12:16], "little")])
    assert glb[:4] == b"glTF" and document["animations"]
    screenshot = page.screenshot()
    assert screenshot.startswith(b"\x89PNG")
    if os.environ.get("FACSIM_UPDATE_DOCS"):
        from PIL import Image

        image = Image.open(io.BytesIO(screenshot)).convert("RGB")
        image.thumbnail((1000, 1000))
        image.save(ROOT / "docs" / "studio.png", optimize=True)


def test_character_and_timeline_files_round_trip(page, tmp_path):
    page.click("button[data-tab=character]")
    page.fill("#seed", "5")
    page.click("#random")
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('random:5')", timeout=120_000)
    with page.expect_download() as download:
        page.click("#character-save")
    saved = tmp_path / "person.yaml"
    download.value.save_as(saved)
    assert "name: random:5" in saved.read_text()
    page.click("button[data-character=ava]")
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('ava')", timeout=120_000)
    page.set_input_files("#character-load", str(saved))
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('random:5')", timeout=120_000)
    page.click("button[data-tab=expression]")
    page.set_input_files("#timeline-load", str(ROOT / "examples" / "overlapping_aus.yaml"))
    page.wait_for_function("studio.editor.doc.tracks.length === 5 && studio.editor.shapes !== null")
    assert [lane["label"][:4] for lane in page.evaluate("() => studio.editor.lanes()")] == ["AU6 ", "AU12", "AU51"]
    with page.expect_download() as download:
        page.click("#timeline-save-json")
    download.value.save_as(tmp_path / "t.json")
    assert json.loads((tmp_path / "t.json").read_text())["tracks"][0]["segments"][0]["easing"] == "smoothstep"


def test_speech_lane_and_analysed_photo(page, tmp_path):
    page.click("#timeline-clear")
    page.evaluate("() => studio.editor.seek(0)")            # a new clip starts at the playhead
    page.fill("#say-text", "Hello there.")
    page.click("#add-speech")
    page.wait_for_function("studio.editor.speech[0] !== undefined && studio.curves && '26' in studio.curves.curves")
    assert [lane["label"] for lane in page.evaluate("() => studio.editor.lanes()")] == ["Speech"]
    doc = page.evaluate("() => studio.editor.doc")
    assert doc["tracks"] == [{"say": "Hello there.", "voice": "slt", "start": 0}]
    end = page.evaluate("() => studio.editor.speech[0].end")
    assert doc["duration"] >= end > 0.5                       # the clip grew to hold the speech
    jaw = page.evaluate("() => Math.max(...studio.curves.curves['26'].left)")
    assert jaw > 0.1                                          # the 3-D view plays the server's speech curves
    page.wait_for_function("studio.audio && studio.audio.src.startsWith('blob:')")   # Play sounds the voice
    skimage_data = pytest.importorskip("skimage.data")
    from PIL import Image

    photo = tmp_path / "astronaut.png"
    Image.fromarray(skimage_data.astronaut()).save(photo)
    page.set_input_files("#analyse-file", str(photo))
    page.wait_for_function("document.querySelector('#analyse-state').textContent.startsWith('astronaut.png:')",
                           timeout=180_000)
    assert "12" in page.input_value("#facs") and not page.is_visible("#analyse-error")
    page.wait_for_function("+document.querySelector('#au-12-left').value > 0 || "
                           "+document.querySelector('#au-12').value > 0")


def test_fifty_concurrent_renders_are_answered_or_refused(server):
    from facsim.studio.loadtest import describe, run

    url, proc = server
    result = run(url, 50, size=64, pid=proc.pid)
    print(describe(result))
    assert result["broken"] == 0, result["broken_examples"]
    assert result["served"] >= 1 and result["served"] + result["refused"] == 50
    assert result["peak_rss"] < 6 * 2**30
    assert result["health_after"]["ok"] and result["health_after"]["pending"] == 0
