"""The studio's HTTP API, endpoint by endpoint, with good and bad input (FastAPI TestClient).

One app (and so one render worker process) serves the whole module; renders are small.
"""
from __future__ import annotations

import json
import subprocess
import sys
import time

import pytest

pytest.importorskip("fastapi")
pytest.importorskip("httpx2", reason="starlette's TestClient needs httpx2 (the studio-test extra)")

from fastapi.testclient import TestClient  # noqa: E402

from facsim.studio.server import create_app  # noqa: E402

BASE = "http://127.0.0.1"
CLIP = {"fps": 10, "tracks": [{"au": 12, "start": 0, "onset": 0.3, "apex": 0.2, "offset": 0.3, "intensity": "C"}]}


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    app = create_app(workdir=tmp_path_factory.mktemp("studio"), allowed_hosts={"127.0.0.1", "localhost"},
                     max_pending=4)
    with TestClient(app, base_url=BASE) as c:
        yield c


def problem(response, status):
    assert response.status_code == status, response.text
    body = response.json()
    assert isinstance(body["error"], str) and body["error"]
    return body


def wait_job(client, job_id, timeout=120):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        job = client.get(f"/api/jobs/{job_id}").json()
        if job["state"] in ("done", "failed", "cancelled"):
            return job
        time.sleep(0.1)
    raise AssertionError(f"job {job_id} did not finish")


# ------------------------------------------------------------- information ---

def test_health(client):
    body = client.get("/api/health").json()
    assert body["ok"] is True and body["max_pending"] == 4


def test_unknown_endpoint_and_method_are_json(client):
    assert "no such" in problem(client.get("/api/nothing"), 404)["error"]
    problem(client.get("/api/render"), 405)


def test_catalogue_serves_the_yaml_regions(client):
    from facsim.studio import compat

    body = client.get("/api/catalogue").json()
    units = {u["code"]: u for u in body["units"]}
    assert units[12]["region"] == compat.catalogue()[12].region == "lower face"
    assert units[1]["unilateral"] and not units[26]["unilateral"]
    assert {u["region"] for u in body["units"]} >= {"upper face", "lower face", "head", "eyes"}
    assert body["intensity_tables"]["hapfacs"]["C"] == 0.55
    assert body["rigid"]["head"]["51"]["degrees"] == 35
    assert "front" in body["views"] and "smoothstep" in body["easings"]


def test_emotions(client):
    body = client.get("/api/emotions").json()
    assert "surprise" in body["names"] and body["tables"]["emfacs"]["presets"]["surprise"] == "1+2+5B+26"


# ------------------------------------------------------------- expressions ---

def test_parse_gives_canonical_text_and_per_side_levels(client):
    body = client.post("/api/parse", json={"expression": "R12C + 14A"}).json()
    assert body["expression"] == "R12C+14A"
    levels = {(u["code"], u["side"]): u["level"] for u in body["units"]}
    assert levels == {(12, "right"): 0.55, (14, "left"): 0.15, (14, "right"): 0.15}


def test_parse_error_names_the_position(client):
    body = problem(client.post("/api/parse", json={"expression": "1+2+AU99"}), 422)
    assert body["position"] == 4 and body["token"] == "AU99" and "AU99" in body["error"]
    assert problem(client.post("/api/parse", json={"expression": "1++2"}), 422)["position"] == 2
    problem(client.post("/api/parse", json={"expression": 12}), 422)
    problem(client.post("/api/parse", json={"expression": "12", "intensities": "nope"}), 422)
    assert "JSON" in problem(client.post("/api/parse", content=b"{nope", headers={"content-type": "application/json"}),
                             400)["error"]


def test_expression_from_slider_levels(client):
    body = client.post("/api/expression", json={"levels": {"12": {"left": 0.55, "right": 0.55}, "1": {"left": 0.3},
                                                           "26": 1.0}}).json()
    assert body["expression"] == "L1B+12C+26"
    assert client.post("/api/expression", json={"levels": {}}).json()["expression"] == "0"
    problem(client.post("/api/expression", json={"levels": {"99": 0.5}}), 422)
    problem(client.post("/api/expression", json={"levels": {"12": 1.5}}), 422)
    problem(client.post("/api/expression", json={"levels": {"26": {"left": 0.2, "right": 0.5}}}), 422)


def test_emotion_presets_and_blends(client):
    assert client.post("/api/emotion", json={"name": "surprise", "table": "emfacs"}).json()["expression"] == "1+2+5B+26"
    half = client.post("/api/emotion", json={"name": "happiness", "table": "emfacs", "intensity": 0.5}).json()
    assert half["expression"] == "6@0.5+12@0.5"
    mix = client.post("/api/emotion", json={"name": "happiness", "blend_with": "surprise", "table": "emfacs"}).json()
    assert mix["expression"] == "1@0.5+2@0.5+5@0.15+6@0.5+12@0.5+26@0.5"
    assert "joy" in problem(client.post("/api/emotion", json={"name": "joy"}), 422)["error"]
    problem(client.post("/api/emotion", json={"name": "surprise", "intensity": "150%"}), 422)


# -------------------------------------------------------------- characters ---

def test_characters_list_presets_and_sliders(client):
    body = client.get("/api/characters").json()
    assert body["presets"]["kwame"]["african"] == 1.0 and "nose/nose-hump" in body["sliders"]


def test_thumbnail_is_a_png_and_unknown_names_404(client):
    r = client.get("/api/characters/ava/thumbnail.png")
    assert r.status_code == 200 and r.content.startswith(b"\x89PNG")
    problem(client.get("/api/characters/nobody/thumbnail.png"), 404)


def test_character_validation_and_random_seed(client):
    assert client.post("/api/character", json={"character": "kwame"}).json()["character"]["name"] == "kwame"
    a = client.post("/api/character", json={"random": 7}).json()["character"]
    assert a == client.post("/api/character", json={"random": 7}).json()["character"]
    assert a != client.post("/api/character", json={"random": 8}).json()["character"]
    problem(client.post("/api/character", json={"character": "nobody"}), 422)
    problem(client.post("/api/character", json={"character": {"age": 200}}), 422)
    assert "slider" in problem(client.post("/api/character", json={"character": {"face": {"nose/bogus": 0.2}}}),
                               422)["error"]
    problem(client.post("/api/character", json={"random": -1}), 422)


def test_character_yaml_round_trip(client):
    params = client.post("/api/character", json={"character": {"gender": 0.3, "age": 40, "asian": 1.0,
                                                                "face": {"nose/nose-hump": 0.4}}}).json()["character"]
    text = client.post("/api/character/yaml", json={"character": params}).text
    assert "nose/nose-hump: 0.4" in text
    assert client.post("/api/character/load", json={"text": text}).json()["character"] == params
    assert "line" in problem(client.post("/api/character/load", json={"text": "age: [1,"}), 422)["error"]
    problem(client.post("/api/character/load", json={"text": "- a list"}), 422)


def test_character_glb_has_au_morph_targets(client):
    r = client.post("/api/character/glb", json={"character": "ava"})
    assert r.status_code == 200 and r.content[:4] == b"glTF"
    length = int.from_bytes(r.content[12:16], "little")
    document = json.loads(r.content[20:20 + length])
    names = document["meshes"][0]["extras"]["targetNames"]
    assert "AU12_L" in names and "AU12_R" in names and "AU26" in names
    problem(client.post("/api/character/glb", json={"character": "nobody"}), 422)


# ----------------------------------------------------------------- renders ---

def test_render_is_byte_identical_to_the_cli(client, tmp_path):
    options = {"size": 64, "view": "three-quarter-left", "antialias": 2, "background": "grey"}
    r = client.post("/api/render", json={"expression": "1+2+5B+26", "character": "kwame", "options": options})
    assert r.status_code == 200 and r.headers["x-facsim-expression"] == "1+2+5B+26"
    out = tmp_path / "cli.png"
    subprocess.run([sys.executable, "-c", "import sys; from facsim.cli import main; sys.exit(main(sys.argv[1:]))",
                    "render", "1+2+5B+26", "-c", "kwame", "--size", "64", "--view", "three-quarter-left",
                    "--antialias", "2", "--background", "grey", "-o", str(out)], check=True, capture_output=True)
    assert r.content == out.read_bytes()


def test_render_without_a_body_is_the_clis_head_alone(client, tmp_path):
    catalogue = client.get("/api/catalogue").json()
    assert catalogue["bodies"] == ["crewneck", "none"] and catalogue["default_body"] == "crewneck"
    options = {"size": 48, "body": "none"}
    r = client.post("/api/render", json={"expression": "12", "character": "liam", "options": options})
    assert r.status_code == 200
    out = tmp_path / "cli.png"
    subprocess.run([sys.executable, "-c", "import sys; from facsim.cli import main; sys.exit(main(sys.argv[1:]))",
                    "render", "12", "-c", "liam", "--size", "48", "--body", "none", "-o", str(out)],
                   check=True, capture_output=True)
    assert r.content == out.read_bytes()
    dressed = client.post("/api/render", json={"expression": "12", "character": "liam", "options": {"size": 48}})
    assert dressed.content != r.content


@pytest.mark.parametrize("body, field", [
    ({"expression": "12", "options": {"size": 4096}}, "size"),
    ({"expression": "12", "options": {"size": 15}}, "size"),
    ({"expression": "12", "options": {"view": "top"}}, "view"),
    ({"expression": "12", "options": {"antialias": 3}}, "antialias"),
    ({"expression": "12", "options": {"background": "#zzzzzz"}}, "background"),
    ({"expression": "12", "options": {"yaw": "left"}}, "yaw"),
    ({"expression": "12", "options": {"body": "tshirt"}}, "body"),
    ({"expression": "12", "engine": "magic"}, "engine"),
    ({"expression": "12+X"}, "expression"),
    ({"expression": "12", "character": {"gender": 2}}, "character"),
])
def test_render_rejects_bad_input_naming_the_field(client, body, field):
    assert problem(client.post("/api/render", json=body), 422)["field"] == field


def test_render_with_the_muscle_engine(client):
    r = client.post("/api/render", json={"expression": "4+6", "engine": "muscle", "options": {"size": 32}})
    assert r.status_code == 200 and r.content.startswith(b"\x89PNG")


def test_render_bad_body_shapes(client):
    assert "Content-Type" in problem(client.post("/api/render", content=b'{"expression": "12"}',
                                                 headers={"content-type": "text/plain"}), 415)["error"]
    problem(client.post("/api/render", json=[1, 2]), 400)
    problem(client.post("/api/render", content=b"x" * (2 << 20), headers={"content-type": "application/json"}), 413)


# ---------------------------------------------------------------- timeline ---

def test_timeline_preview_samples_the_document(client):
    body = client.post("/api/timeline/preview", json={"timeline": CLIP}).json()
    assert body["frames"] == 8 and body["fps"] == 10
    assert max(body["curves"]["12"]["left"]) == pytest.approx(0.55)
    bad = {"tracks": [{"au": 12, "segments": [{"start": 1.4, "end": 0.2, "to": 1}]}]}
    body = problem(client.post("/api/timeline/preview", json={"timeline": bad}), 422)
    assert body["location"] == "tracks[0].segments[0].end"
    problem(client.post("/api/timeline/preview", json={"timeline": {"tracks": [{"au": 12, "end": 1e6}]}}), 422)
    problem(client.post("/api/timeline/preview", json={"timeline": "no"}), 422)


def test_timeline_load_and_save_formats(client):
    yaml_text = client.post("/api/timeline/save", json={"timeline": CLIP, "format": "yaml"}).text
    json_text = client.post("/api/timeline/save", json={"timeline": CLIP, "format": "json"}).text
    from_yaml = client.post("/api/timeline/load", json={"name": "a.yaml", "text": yaml_text}).json()["timeline"]
    from_json = client.post("/api/timeline/load", json={"name": "a.json", "text": json_text}).json()["timeline"]
    assert from_yaml == from_json and from_yaml["tracks"][0]["intensity"] == 0.55
    facs = client.post("/api/jobs", json={"kind": "facs", "timeline": CLIP}).json()
    assert wait_job(client, facs["id"])["state"] == "done"
    text = client.get(f"/api/jobs/{facs['id']}/download").text
    assert client.post("/api/timeline/load", json={"name": "a.facs", "text": text}).json()["timeline"] == from_yaml
    assert "line 1" in problem(client.post("/api/timeline/load", json={"name": "a.yaml", "text": "tracks: [1,"}),
                               422)["error"]
    problem(client.post("/api/timeline/load", json={"name": "a.txt", "text": "x"}), 422)
    problem(client.post("/api/timeline/save", json={"timeline": CLIP, "format": "xml"}), 422)


def test_stimulus_defaults_are_one_second_each(client):
    body = client.post("/api/timeline/stimulus", json={"emotion": "surprise"}).json()["timeline"]
    assert body["tracks"] == [{"emotion": "surprise", "start": 0, "onset": 1, "apex": 1, "offset": 1, "intensity": 1,
                               "easing": "linear"}]
    problem(client.post("/api/timeline/stimulus", json={"emotion": "joy"}), 422)


# -------------------------------------------------------------------- jobs ---

def test_video_job_reports_progress_then_downloads(client):
    job = client.post("/api/jobs", json={"kind": "video", "format": "gif", "timeline": CLIP,
                                         "options": {"size": 32}}).json()
    events = []
    with client.stream("GET", f"/api/jobs/{job['id']}/events") as stream:
        for line in stream.iter_lines():
            if line.startswith("event:"):
                events.append(line.split(":", 1)[1].strip())
    assert events[-1] == "done" and events.count("progress") >= 2
    r = client.get(f"/api/jobs/{job['id']}/download")
    assert r.status_code == 200 and r.content[:6] == b"GIF89a" and r.headers["content-type"] == "image/gif"


@pytest.mark.parametrize("kind, magic", [("glb", b"glTF"), ("arkit-csv", b"Timecode"), ("png", b"\x89PNG")])
def test_export_jobs(client, kind, magic):
    body = {"kind": kind, "timeline": CLIP, "expression": "6+12", "options": {"size": 32}}
    job = client.post("/api/jobs", json=body).json()
    assert wait_job(client, job["id"])["state"] == "done"
    assert client.get(f"/api/jobs/{job['id']}/download").content.startswith(magic)


def test_a_glb_export_leaves_the_body_out_when_asked(client):
    meshes = {}
    for body in ("crewneck", "none"):
        job = client.post("/api/jobs", json={"kind": "glb", "timeline": CLIP, "options": {"body": body}}).json()
        assert wait_job(client, job["id"])["state"] == "done"
        data = client.get(f"/api/jobs/{job['id']}/download").content
        length = int.from_bytes(data[12:16], "little")           # the glb's JSON chunk
        meshes[body] = {m["name"] for m in json.loads(data[20:20 + length])["meshes"]}
    assert "body" in meshes["crewneck"] and "body" not in meshes["none"]
    problem(client.post("/api/jobs", json={"kind": "glb", "timeline": CLIP, "options": {"body": "cape"}}), 422)


def test_jobs_refuse_bad_input_and_unknown_ids(client):
    problem(client.post("/api/jobs", json={"kind": "pdf", "timeline": CLIP}), 422)
    problem(client.post("/api/jobs", json={"kind": "video", "timeline": CLIP, "format": "avi"}), 422)
    problem(client.post("/api/jobs", json={"kind": "video", "timeline": CLIP, "options": {"size": 33}}), 422)
    problem(client.post("/api/jobs", json={"kind": "glb", "timeline": {"tracks": [{"au": 99, "end": 1}]}}), 422)
    problem(client.get("/api/jobs/0123456789abcdef0123456789abcdef"), 404)
    problem(client.get("/api/jobs/..%2F..%2Fetc%2Fpasswd/download"), 404)
    problem(client.post("/api/jobs/nope/cancel"), 404)


def test_cancel_stops_a_running_video(client):
    long_clip = {"fps": 30, "tracks": [{"au": 12, "start": 0, "onset": 5, "apex": 5, "offset": 5}]}
    job = client.post("/api/jobs", json={"kind": "video", "format": "mp4", "timeline": long_clip,
                                         "options": {"size": 32}}).json()
    while client.get(f"/api/jobs/{job['id']}").json()["done"] < 2:
        time.sleep(0.05)
    assert problem(client.get(f"/api/jobs/{job['id']}/download"), 409)
    client.post(f"/api/jobs/{job['id']}/cancel")
    final = wait_job(client, job["id"])
    assert final["state"] == "cancelled" and final["done"] < final["total"]


def test_full_queue_answers_503_at_once(tmp_path):
    app = create_app(workdir=tmp_path, max_pending=1)
    long_clip = {"fps": 30, "tracks": [{"au": 12, "start": 0, "onset": 5, "apex": 5, "offset": 5}]}
    with TestClient(app, base_url=BASE) as c:
        job = c.post("/api/jobs", json={"kind": "video", "timeline": long_clip, "options": {"size": 32}}).json()
        r = c.post("/api/render", json={"expression": "12", "options": {"size": 32}})
        assert r.status_code == 503 and r.headers["retry-after"] and "full" in r.json()["error"]
        c.post(f"/api/jobs/{job['id']}/cancel")
        wait_job(c, job["id"])
        assert c.post("/api/render", json={"expression": "12", "options": {"size": 32}}).status_code == 200
        assert c.get("/api/health").json()["refused"] == 1


def test_jobs_write_only_in_their_folder(tmp_path):
    app = create_app(workdir=tmp_path / "work")
    with TestClient(app, base_url=BASE) as c:
        job = c.post("/api/jobs", json={"kind": "facs", "timeline": CLIP}).json()
        wait_job(c, job["id"])
    files = [p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*") if p.is_file()]
    assert files == [f"work/jobs/{job['id']}/timeline.facs"]


# ---------------------------------------------------------------- security ---

def test_token_is_required_when_set(tmp_path):
    app = create_app(workdir=tmp_path, token="s3cret")
    with TestClient(app, base_url=BASE) as c:
        assert "token" in problem(c.get("/api/health"), 401)["error"]
        problem(c.get("/api/health", headers={"X-Facsim-Token": "wrong"}), 401)
        assert c.get("/api/health", headers={"X-Facsim-Token": "s3cret"}).status_code == 200
        page = c.get("/?token=s3cret")
        assert page.status_code == 200 and "facsim_token" in page.headers["set-cookie"]
        assert c.get("/api/health").status_code == 200       # the cookie from the page


def test_foreign_host_header_is_refused(client):
    assert "not allowed" in problem(client.get("/api/health", headers={"host": "evil.example"}), 403)["error"]


def test_page_static_files_and_three_js(client):
    page = client.get("/")
    assert page.status_code == 200 and "importmap" in page.text
    assert client.get("/static/app.js").status_code == 200
    problem(client.get("/static/secret.py"), 404)
    three = client.get("/vendor/three/build/three.module.js")
    assert three.status_code == 200 and "three.core.js" in three.text
    assert client.get("/vendor/three/addons/loaders/GLTFLoader.js").status_code == 200
    problem(client.get("/vendor/three/addons/../../LICENSE"), 404)
    problem(client.get("/vendor/three/other/x.js"), 404)


def test_three_js_integrity_check_refuses_other_bytes():
    from facsim.studio.vendor import VendorError, check_integrity

    with pytest.raises(VendorError, match="sha512"):
        check_integrity(b"not three.js")


# ------------------------------------------------------------------ speech ---

SPEECH = {"fps": 10, "tracks": [{"au": 12, "start": 0, "onset": 0.3, "apex": 0.4, "offset": 0.3},
                                 {"say": "Hello there.", "voice": "slt", "start": 0.2}]}


def test_speech_clip_is_sampled_and_drawn(client):
    body = client.post("/api/timeline/preview", json={"timeline": SPEECH}).json()
    speech = body["speech"]["1"]
    assert speech["start"] == 0.2 and speech["end"] > 0.6 and "Hello there." in speech["label"]
    assert body["length"] == pytest.approx(speech["end"])
    assert max(body["curves"]["26"]["left"]) > 0.1            # the jaw moves while it speaks
    assert max(body["shapes"]["levels"][1]) > 0.1 and body["shapes"]["levels"][1][0] < 0.05
    bad_voice = {"tracks": [{"say": "Hi.", "voice": "nobody"}]}
    assert "nobody" in problem(client.post("/api/timeline/preview", json={"timeline": bad_voice}), 422)["error"]
    recording = {"tracks": [{"audio": "/etc/passwd", "transcript": "root"}]}
    refused = problem(client.post("/api/timeline/preview", json={"timeline": recording}), 422)
    assert refused["location"] == ["tracks", 0, "audio"]
    problem(client.post("/api/jobs", json={"kind": "video", "timeline": recording}), 422)
    assert "slt" in client.get("/api/catalogue").json()["voices"]
    wav = client.post("/api/timeline/audio", json={"timeline": SPEECH})
    assert wav.status_code == 200 and wav.content[:4] == b"RIFF" and wav.headers["content-type"] == "audio/wav"
    import io

    from scipy.io import wavfile

    rate, samples = wavfile.read(io.BytesIO(wav.content))
    assert len(samples) / rate == pytest.approx(body["frames"] / 10, abs=1e-3) and abs(samples).max() > 1000
    assert client.post("/api/timeline/audio", json={"timeline": CLIP}).status_code == 204


def test_video_of_a_speech_clip_carries_its_audio(client, tmp_path):
    from facsim.cli.analysis import has_audio

    job = client.post("/api/jobs", json={"kind": "video", "format": "mp4", "timeline": SPEECH,
                                         "options": {"size": 32}}).json()
    assert wait_job(client, job["id"])["state"] == "done"
    clip = tmp_path / "speech.mp4"
    clip.write_bytes(client.get(f"/api/jobs/{job['id']}/download").content)
    assert has_audio(clip)


# ----------------------------------------------------------------- analyse ---

def analyse(client, data: bytes, kind="image/png"):
    return client.post("/api/analyse", content=data, headers={"content-type": kind})


def png_of(array) -> bytes:
    import io

    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(array).save(buf, format="PNG")
    return buf.getvalue()


def test_analyse_a_photograph_gives_its_facs(client):
    skimage_data = pytest.importorskip("skimage.data")
    job = analyse(client, png_of(skimage_data.astronaut()))
    assert job.status_code == 202 and job.json()["kind"] == "analyse"
    assert wait_job(client, job.json()["id"])["state"] == "done"
    result = client.get(f"/api/jobs/{job.json()['id']}/download").json()
    assert result["kind"] == "image" and result["found"] == 1
    assert "12" in result["expression"]                         # she smiles
    assert client.post("/api/parse", json={"expression": result["expression"]}).status_code == 200


def test_analyse_a_video_gives_a_timeline(client, tmp_path):
    skimage_data = pytest.importorskip("skimage.data")
    import imageio.v2 as imageio

    path = tmp_path / "clip.mp4"
    with imageio.get_writer(path, fps=5, macro_block_size=16) as writer:
        for _ in range(5):
            writer.append_data(skimage_data.astronaut())
    job = analyse(client, path.read_bytes(), "video/mp4").json()
    events = []
    with client.stream("GET", f"/api/jobs/{job['id']}/events") as stream:
        events = [line.split(":", 1)[1].strip() for line in stream.iter_lines() if line.startswith("event:")]
    assert events[-1] == "done" and events.count("progress") >= 2
    result = client.get(f"/api/jobs/{job['id']}/download").json()
    assert result["kind"] == "video" and result["frames"] == 5
    assert any(t.get("au") == 12 for t in result["timeline"]["tracks"])
    preview = client.post("/api/timeline/preview", json={"timeline": result["timeline"]}).json()
    # what the 3-D view plays (the side the fit gives the smile follows the AU basis; either will do)
    assert preview["frames"] == 5 and max(max(curve) for curve in preview["curves"]["12"].values()) > 0


def test_analyse_refuses_what_is_not_a_face_picture(client):
    assert "not an image" in problem(analyse(client, b"hello, world", "application/octet-stream"), 415)["error"]
    problem(analyse(client, b"", "image/png"), 422)
    problem(analyse(client, b"\x89PNG\r\n\x1a\n", "text/plain"), 415)     # a form elsewhere could send this
    from facsim.studio.requests import MAX_UPLOAD

    assert str(MAX_UPLOAD) in problem(analyse(client, b"\xff\xd8\xff" + bytes(MAX_UPLOAD)), 413)["error"]
    broken = wait_job(client, analyse(client, b"\x89PNG\r\n\x1a\n" + b"junk" * 16).json()["id"])
    assert broken["state"] == "failed" and "cannot read the uploaded image" in broken["error"]
    assert "jobs" not in broken["error"]                                   # no server path in the message
    import numpy as np

    blank = wait_job(client, analyse(client, png_of(np.full((96, 96, 3), 200, np.uint8))).json()["id"])
    assert blank["state"] == "failed" and "no face found in the uploaded image" in blank["error"]
