"""The video frame loop's shortcuts give the frames that drawing everything, in order, gives.

- still hair kept as pixels between the frames of a video (renderer), redrawn when the head
  moves, never outside a video;
- FXAA over the drawn geometry's box only;
- the engine stepped in a forked child a frame ahead of the drawing (pipeline).
"""
from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

SIZE = 128


def _renderer(face):
    from facsim.render.renderer import Renderer

    return Renderer(face.topology, size=SIZE, antialias=1, aa_method="fxaa", background=(1.0, 1.0, 1.0))


def _frame(renderer, face, expression):
    d = face.deform(expression)
    positions = np.asarray(d.positions, np.float32)
    return renderer.render(positions, appearance=face.appearance, camera=face.camera(size=(SIZE, SIZE)),
                           wrinkle=d.wrinkle, crease_phase=d.crease_phase, occlusion=face.shading_occlusion,
                           proxies=face.proxy_draws(positions))


def test_kept_hair_gives_the_frame_drawing_everything_gives(face_of):
    face = face_of("ava")
    with _renderer(face) as r:
        with r.sequence():
            for expression in ("12@10%", "12@20%", "6+12@30%", "6+12@40%"):
                kept = _frame(r, face, expression)
            assert r._hair_moving is not None, "a smile moves a few sideburn cards: the rest should be kept"
            assert 0 < r._hair_moving[next(iter(r._hair_moving))].mean() < 0.25
        for expression in ("12@10%", "12@20%", "6+12@30%", "6+12@40%"):  # not a video: every frame in full
            full = _frame(r, face, expression)
            assert r._hair_moving is None
    with _renderer(face) as fresh:
        assert np.array_equal(_frame(fresh, face, "6+12@40%"), full)
    diff = np.abs(kept.astype(int) - full.astype(int)).max(axis=2)
    # The kept cards keep the shading of the frame they were drawn in; the sideburns' motion moves
    # the hair volume's centre by a hair, which changes that shading by a few levels at most
    # (up to 5 on a lone strand pixel under the frontal studio key).
    assert diff.max() <= 6 and (diff > 0).mean() < 0.01


def test_head_motion_redraws_all_hair(face_of):
    face = face_of("ava")
    with _renderer(face) as r, r.sequence():
        for expression in ("51@20%", "51@40%", "51@60%"):
            _frame(r, face, expression)
        assert r._hair_moving is None
        _frame(r, face, "51@60%")  # the head holds still: the hair is kept again
        assert r._hair_moving is not None


def test_fxaa_filters_the_drawn_box_and_copies_the_rest_exactly(face_of, monkeypatch):
    from facsim.render.renderer import Renderer

    face = face_of("kwame")
    with _renderer(face) as r:
        boxed = _frame(r, face, "12")
        x, y, w, h = r._content_box
        assert w * h < 0.9 * SIZE * SIZE
        monkeypatch.setattr(Renderer, "_screen_box", lambda self, point_sets: None)
        whole = _frame(r, face, "12")
    assert np.array_equal(boxed, whole)
    # The top row is background, but for the crop's outermost coils grazing it (a level or a few
    # of 255): FXAA must not wrap the neck's dark skin around into it.
    assert (boxed[0, :, :3] >= 240).all(), "the top row is background: FXAA must not wrap the neck around"


FORKED = textwrap.dedent("""
    import multiprocessing, os
    import numpy as np
    from facsim.face import Face
    from facsim.pipeline import deformations
    from facsim.timeline.builders import stimulus_timeline
    from facsim.timeline.sampling import sample_frames

    face = Face("ava")
    frames = sample_frames(stimulus_timeline("happiness", 0.2, 0.1, 0.2, 30), 30)
    with deformations(face, frames) as stream:
        forked = [d.positions for d in stream]
        assert multiprocessing.active_children(), "expected the engine in a child process"
    os.environ["FACSIM_SERIAL_FRAMES"] = "1"
    with deformations(face, frames) as stream:
        serial = [d.positions for d in stream]
        assert not multiprocessing.active_children()
    assert len(forked) == len(serial) == len(frames)
    assert all(np.array_equal(a, b) for a, b in zip(forked, serial))
    del os.environ["FACSIM_SERIAL_FRAMES"]

    class Broken:
        def start_animation(self):
            raise ValueError("no engine for this face")

    try:
        with deformations(Broken(), frames) as stream:
            list(stream)
    except ValueError as exc:
        assert "no engine for this face" in str(exc)
    else:
        raise AssertionError("the child's error did not reach the parent")
    print("ok")
""")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="frames are deformed in a forked child on Linux")
def test_forked_engine_gives_the_serial_frames_and_its_errors():
    # A fresh process: this one may already hold a GL context, where forking is refused.
    done = subprocess.run([sys.executable, "-c", FORKED], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip().endswith("ok")


def test_repeated_activations_reuse_a_frame_within_the_budget_and_only_for_stateless_engines(face_of):
    from facsim.facs.activations import Activations
    from facsim.pipeline import frame_sources
    from facsim.timeline.builders import stimulus_timeline
    from facsim.timeline.sampling import sample_frames

    frames = sample_frames(stimulus_timeline("happiness", 1.0, 1.0, 1.0, 30), 30)
    sources = frame_sources(face_of("ava"), frames)  # registers: each frame its activations alone
    assert len(set(sources)) == 31, "onset drawn, apex held, offset replaying the onset"
    assert sources[45] == 30 and sources[61] == 29 and sources[89] == 1
    assert all(frames[s].levels == frames[i].levels and s <= i for i, s in enumerate(sources))
    a, b = Activations({(12, "left"): 0.5}), Activations({(12, "right"): 0.5})
    # Room for one kept image: b is drawn again, as it is not kept while a is.
    assert frame_sources(None, [a, b, a, b], frame_bytes=10, budget=10) == [0, 1, 0, 3]
    assert frame_sources(None, [a, b, a, b], frame_bytes=10, budget=0) == [0, 1, 2, 3]
    muscle = type("MuscleFace", (), {"engine_name": "muscle"})()
    assert frame_sources(muscle, [a, a, a]) == [0, 1, 2], "a stateful engine draws every frame"


def test_a_video_with_repeats_gives_the_frames_drawing_every_frame_gives(tmp_path, face_of, monkeypatch):
    from PIL import Image

    import facsim.pipeline as pipeline
    from facsim.timeline.builders import stimulus_timeline

    face = face_of("ava")
    clip = stimulus_timeline("12+26", onset=0.2, apex=0.2, offset=0.2, fps=10)
    reused = pipeline.animate(clip, tmp_path / "reused", face=face, size=64)
    monkeypatch.setattr(pipeline, "frame_sources", lambda face, frames, **kw: list(range(len(frames))))
    every = pipeline.animate(clip, tmp_path / "every", face=face, size=64)
    a = [np.asarray(Image.open(p), int) for p in sorted(reused.glob("*.png"))]
    b = [np.asarray(Image.open(p), int) for p in sorted(every.glob("*.png"))]
    assert len(a) == len(b) == 6
    assert np.array_equal(a[3], a[2]) and np.array_equal(a[4], a[2]) and np.array_equal(a[5], a[1])
    # Drawn again, a repeated frame differs at most by the kept hair's level or two (see the test above).
    assert max(np.abs(x - y).max() for x, y in zip(a, b)) <= 3
