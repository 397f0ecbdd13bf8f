"""The user-facing face: a character, an engine and a renderer behind one object.

Examples
--------
>>> face = Face("ava")                                    # doctest: +SKIP
>>> image = face.render("6+12", view="three-quarter-left") # doctest: +SKIP
>>> face.save("smile.png", "6+12C", size=512)             # doctest: +SKIP
"""
from __future__ import annotations

from functools import cached_property, lru_cache
from typing import NamedTuple

import numpy as np

from facsim.head.assets import load_face_data
from facsim.head.character import Character, resolve_character
from facsim.facs.activations import Activations, activations
from facsim.head.mesh import HeadModel, build_head

ENGINES = ("registers", "muscle")
#: Framing uses the skin above this height below the chin (dm), so a portrait
#: shows the whole head with a little neck, the same in every frame.
NECK_SHOWN = 0.45
#: Bump when the occlusion bake changes, so cached bakes are redone.
OCCLUSION_VERSION = 1


@lru_cache(maxsize=1)
def load_head() -> HeadModel:
    """The head model, built once per process from the cached face data."""
    return build_head(load_face_data())


def engine_class(name: str):
    """The deformation engine class called ``name`` (imported lazily)."""
    if name == "registers":
        from facsim.engines.registers import RegisterEngine

        return RegisterEngine
    if name == "muscle":
        from facsim.engines.muscle import MuscleEngine

        return MuscleEngine
    raise ValueError(f"unknown engine {name!r}; choose from {', '.join(ENGINES)}")


def to_activations(expression, *, intensities: str = "hapfacs") -> Activations:
    """Activations from a FACS string, an Expression, Activations or None (neutral)."""
    if expression is None:
        return Activations()
    if isinstance(expression, Activations):
        return expression
    if isinstance(expression, str):
        from facsim.facs.notation import parse

        expression = parse(expression, intensities=intensities)
    return activations(expression)


class Face:
    """A character's face: deform it with FACS, render it.

    Parameters
    ----------
    character : str, mapping or Character
        A preset name (``facsim characters``), ``"random:SEED"``, or parameters.
    engine : {"registers", "muscle"}
        How AUs move the face: HapFACS-style morph targets, or the muscle engine.
    """

    def __init__(self, character="ava", *, engine: str = "registers"):
        self.character: Character = resolve_character(character)
        self.head = load_head()
        self.engine_name = engine
        self._engine_class = engine_class(engine)
        self._renderers: dict = {}

    @cached_property
    def data(self):
        return load_face_data()

    @cached_property
    def base_positions(self) -> np.ndarray:
        """The character's neutral base mesh (19158, 3)."""
        from facsim.head.character import character_offsets

        return character_offsets(self.character, self.data)

    @cached_property
    def engine(self):
        """The engine: a callable ``activations -> geometry positions``."""
        return self._engine_class(self.head, self.data, self.character, self.base_positions)

    @cached_property
    def neutral(self) -> np.ndarray:
        """Neutral geometry positions (N_geo, 3)."""
        return self.head.positions(self.base_positions)

    @cached_property
    def appearance(self):
        from facsim.head.appearance import character_appearance

        return character_appearance(self.character, self.head)

    @cached_property
    def occlusion(self) -> np.ndarray:
        """Ambient visibility per vertex (1 open … 0 enclosed), baked once on the neutral face.

        Sockets and creases change little with expression, so one bake per
        character serves every frame; it is cached on disk by the character's parameters.
        """
        import hashlib

        from facsim.head.assets import cache_dir
        from facsim.atomic import atomic_write
        from facsim.render.occlusion import bake_occlusion

        key = hashlib.sha256(repr((OCCLUSION_VERSION, self.character.with_(name="", description="", colors={})))
                             .encode()).hexdigest()[:16]
        path = cache_dir() / "occlusion" / f"{key}.npy"
        try:
            return np.load(path)
        except (OSError, ValueError):
            pass
        occlusion = bake_occlusion(self.head.topology, self.neutral)
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write(path, lambda tmp: tmp.write_bytes(_npy_bytes(occlusion)))
        return occlusion

    def deform(self, expression=None) -> np.ndarray:
        """Geometry positions (N_geo, 3) showing ``expression`` (FACS string, Expression or Activations)."""
        act = to_activations(expression)
        return self.engine(act) if act else self.neutral

    def camera(self, *, view: str = "front", yaw=None, pitch=None, projection="perspective", size=(512, 512), fov_deg=None):
        """A camera framing this character's neutral head and upper neck (the same for every frame)."""
        return self._camera(view, yaw, pitch, projection, tuple(size), fov_deg)

    @lru_cache(maxsize=16)  # noqa: B019 — a Face lives as long as its renders
    def _camera(self, view, yaw, pitch, projection, size, fov_deg):
        from facsim.render.camera import DEFAULT_FOV_DEG, frame_points

        skin = self.neutral[self.head.skin]
        chin = float(self.head.joint(self.base_positions, "joint-jaw")[1])
        keep = skin[:, 1] > chin - NECK_SHOWN
        width, height = size
        return frame_points(skin[keep], view=view, yaw=yaw, pitch=pitch, projection=projection,
                            fov_deg=fov_deg or DEFAULT_FOV_DEG, margin=0.06, aspect=width / height)

    def renderer(self, size=(512, 512), *, antialias=4, background=(1.0, 1.0, 1.0)):
        """A renderer for this head (cached per size, anti-aliasing and background).

        ``antialias``: MSAA samples (1 = off, 4 = llvmpipe's best) or ``"fxaa"``
        (post-process edge smoothing at about the cost of no AA).
        """
        from facsim.render.renderer import Renderer

        key = (tuple(size), antialias, None if background is None else tuple(background))
        if key not in self._renderers:
            method = "fxaa" if antialias == "fxaa" else "msaa"
            self._renderers[key] = Renderer(self.head.topology, size=tuple(size), background=background,
                                            antialias=1 if method == "fxaa" else int(antialias), aa_method=method)
        return self._renderers[key]

    def render(self, expression=None, *, view: str = "front", yaw=None, pitch=None, size=512,
               projection: str = "perspective", background=(1.0, 1.0, 1.0), antialias=4,
               positions=None, wrinkle=None, crease_phase=None) -> np.ndarray:
        """Render ``expression`` to an (H, W, 4) uint8 RGBA image.

        ``background=None`` gives a transparent background. ``positions`` renders
        given geometry instead of deforming (e.g. from another engine), with its
        ``wrinkle`` and ``crease_phase`` if it has them (see :meth:`Renderer.render`).
        """
        size = _size_pair(size)
        if positions is None:
            act = to_activations(expression)
            positions = self.engine(act) if act else self.neutral
            if wrinkle is None and act:  # the neutral face has no creases
                wrinkle = getattr(self.engine, "last_wrinkle", None)
                crease_phase = getattr(self.engine, "last_crease_phase", None)
        camera = self.camera(view=view, yaw=yaw, pitch=pitch, projection=projection, size=size)
        return self.renderer(size, antialias=antialias, background=background).render(
            np.asarray(positions, np.float32), appearance=self.appearance, camera=camera, wrinkle=wrinkle,
            crease_phase=crease_phase, occlusion=self.occlusion,
        )

    def start_animation(self) -> "Animation":
        """A frame stepper for videos (engines with state apply only each frame's change)."""
        if hasattr(self.engine, "reset"):
            self.engine.reset()
        return Animation(self.engine)

    def save(self, path, expression=None, **render_options) -> np.ndarray:
        """Render and write a PNG atomically; returns the image."""
        from facsim.media.images import write_png

        image = self.render(expression, **render_options)
        write_png(path, image)
        return image

    def close(self) -> None:
        for renderer in self._renderers.values():
            renderer.close()
        self._renderers.clear()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _npy_bytes(array: np.ndarray) -> bytes:
    import io

    buf = io.BytesIO()
    np.save(buf, array)
    return buf.getvalue()


class Frame(NamedTuple):
    """One deformed frame: what :meth:`Face.render` takes as ``**frame._asdict()``."""

    positions: np.ndarray
    wrinkle: np.ndarray | None = None        # skin compression (muscle engine)
    crease_phase: np.ndarray | None = None   # where across its furrows each vertex lies


class Animation:
    """Steps an engine frame by frame: ``frame = animation.step(activations)``, a :class:`Frame`."""

    def __init__(self, engine):
        self.engine = engine
        self._stateful = hasattr(engine, "step")

    def step(self, act: Activations) -> Frame:
        positions = self.engine.step(act) if self._stateful else self.engine(act)
        return Frame(positions, getattr(self.engine, "last_wrinkle", None),
                     getattr(self.engine, "last_crease_phase", None))


def _size_pair(size) -> tuple[int, int]:
    if isinstance(size, (int, np.integer)):
        size = (int(size), int(size))
    width, height = (int(v) for v in size)
    if not (16 <= width <= 8192 and 16 <= height <= 8192):
        raise ValueError(f"image size must be between 16 and 8192 pixels per side, got {width}x{height}")
    return width, height
