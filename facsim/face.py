"""The user-facing face: a character, an engine and a renderer behind one object.

Examples
--------
>>> face = Face("ava")                                    # doctest: +SKIP
>>> image = face.render("6+12", view="three-quarter-left") # doctest: +SKIP
>>> face.save("smile.png", "6+12C", size=512)             # doctest: +SKIP
"""
from __future__ import annotations

from functools import cached_property, lru_cache

import numpy as np

from facsim.engines import DEFAULT_ENGINE, engine_class
from facsim.engines.base import Deformation, Engine
from facsim.facs.activations import Activations, activations
from facsim.head.assets import load_face_data
from facsim.head.character import Character, resolve_character
from facsim.head.mesh import HeadModel, build_head
from facsim.render.options import DEFAULT_BODY, RenderOptions

#: Framing uses the skin above this height below the chin (dm), so a portrait
#: shows the whole head with a little neck, the same in every frame.
NECK_SHOWN = 0.45
#: Bump when the occlusion bake changes, so cached bakes are redone.
OCCLUSION_VERSION = 4  # 4: the relaxed lids at rest (lids.yaml); 3 was a withdrawn rest (rest_pose.yaml) whose bakes may linger in caches


@lru_cache(maxsize=1)
def load_head() -> HeadModel:
    """The head model, built once per process from the cached face data."""
    return build_head(load_face_data())


@lru_cache(maxsize=4)
def load_body(style: str):
    """The body's topology in garment ``style`` (:func:`facsim.head.body.build_body`), built once per process."""
    from facsim.head.body import build_body

    return build_body(load_face_data(), load_head(), style)


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
        How AUs move the face: HapFACS-style morph targets, or the muscle engine
        (see :data:`facsim.engines.ENGINES`).
    intensities : {"hapfacs", "facshuman"}
        What the letters A–E of FACS strings given to this face mean.
    """

    def __init__(self, character="ava", *, engine: str = DEFAULT_ENGINE, intensities: str = "hapfacs"):
        from facsim.facs.catalogue import INTENSITY_TABLES

        if intensities not in INTENSITY_TABLES:
            raise ValueError(f"intensities must be one of {', '.join(INTENSITY_TABLES)}, got {intensities!r}")
        self.character: Character = resolve_character(character)
        self.head = load_head()
        self.engine_name = engine
        self.intensities = intensities
        self._engine_class = engine_class(engine)
        self._renderers: dict = {}
        self._body_rigs: dict = {}

    @cached_property
    def data(self):
        return load_face_data()

    @cached_property
    def base_positions(self) -> np.ndarray:
        """The character's neutral base mesh (19158, 3)."""
        from facsim.head.character import character_positions

        return character_positions(self.character, self.data)

    @cached_property
    def engine(self) -> Engine:
        """The deformation engine, built once for this character."""
        return self._engine_class(self.head, self.data, self.character, self.base_positions)

    @cached_property
    def neutral(self) -> np.ndarray:
        """Neutral geometry positions (N_geo, 3): the engine's rest (the sculpted face with relaxed
        lids, facsim.engines.lids.RestLids), so every expression starts from it."""
        return np.asarray(self.engine.neutral, np.float32)

    @cached_property
    def proxies(self) -> list:
        """The character's hair, brow and lash proxies (:class:`facsim.head.proxies.BoundProxy`)."""
        from facsim.head.proxies import bind_character_proxies

        return bind_character_proxies(self.character, self.head, self.base_positions, self.neutral)

    @cached_property
    def scalp(self):
        """The fine hair on the skin under the hair's cards (a ``"scalp"`` BoundProxy), or None."""
        import hashlib

        from facsim.head.assets import cache_dir
        from facsim.head.proxies import bind_scalp, hair_table, hair_volume
        from facsim.head.scalp import CROP_EDGE, CROP_ROUNDING, HAIRLINE_RISE, HAIRLINE_THINNING, RISE_FIT_WEIGHT, VERSION

        hair = [b for b in self.proxies if b.proxy.kind == "hair"]
        if not hair:
            return None
        # Cached on disk like the occlusion bake: by the head's shape, the style and its table.
        shape = self.character.with_(name="", description="", colors={}, hair="", brows="", lashes="")
        key = hashlib.sha256(repr((VERSION, HAIRLINE_THINNING, HAIRLINE_RISE, RISE_FIT_WEIGHT, shape, hair[0].proxy.name,
                                   (hair[0].crop, hair_table()["crops"][hair[0].crop], CROP_ROUNDING, CROP_EDGE)
                                   if hair[0].crop else "", hair_table().get("scalp"),
                                   hair_volume(hair[0].proxy.name), hair_table().get("snug")))
                             .encode()).hexdigest()[:16]
        return bind_scalp(hair[0], self.head, self.neutral, cache=cache_dir() / "scalp" / f"{key}.npy")

    @cached_property
    def wisps(self):
        """Loose strands over the hair's cards (a ``"wisps"`` BoundProxy, facsim.head.wisps), or None."""
        from facsim.head.proxies import bind_wisps

        hair = [b for b in self.proxies if b.proxy.kind == "hair" and not b.crop]  # a crop has no strands to stray
        return bind_wisps(hair[0], self.head, self.neutral) if hair else None

    @property
    def _drawn_proxies(self) -> list:
        """What the renderer draws: the scalp layer first (under every card), then the hair,
        its loose strands, brows and lashes. A close crop is its scalp layer alone."""
        out = [self.scalp] if self.scalp is not None else []
        for bound in self.proxies:
            if bound.crop:
                continue
            out.append(bound)
            if bound.proxy.kind == "hair" and self.wisps is not None:
                out.append(self.wisps)
        return out

    @cached_property
    def proxy_meshes(self) -> list:
        """What the renderer uploads of each proxy (:class:`facsim.render.proxies.ProxyMesh`), in draw order."""
        from facsim.render.proxies import ProxyMesh

        return [ProxyMesh(b.proxy.name, b.proxy.kind, b.proxy.triangles, b.proxy.corner_vertex, b.proxy.uv,
                          b.proxy.texture, b.depth,
                          b.neutral if b.proxy.kind in ("hair", "wisps") or b.crop or b.coil > 0.0 else None,
                          self._card_cover(b) if b.proxy.kind == "hair" else None, b.coil > 0.0,
                          b.strand_points, b.strand_width,
                          self._hair_end_height if b.proxy.kind in ("hair", "wisps") else None, bool(b.crop),
                          b.hairline)
                for b in self._drawn_proxies]

    @cached_property
    def _hair_end_height(self) -> float:
        """Where long hair ends (y on the neutral face, dm): ``ends_above_neck_base_mm`` (``hair.yaml``)
        above the lowest point of the head's skin, where the neck meets the shoulders."""
        from facsim.head.proxies import hair_table

        neck_base = float(self.neutral[: self.head.skin_vertex_count, 1].min())
        return neck_base + float(hair_table()["ends_above_neck_base_mm"]) / 100.0

    def _card_cover(self, bound) -> np.ndarray | None:
        """The scalp's hair density under ``bound``'s cards (:func:`facsim.head.scalp.card_cover`)."""
        from facsim.head.scalp import card_cover

        if self.scalp is None:
            return None
        skin = self.head.skin_vertex_count
        return card_cover(bound.neutral, self.neutral[:skin], self._scalp_density[:skin])

    @cached_property
    def _scalp_density(self) -> np.ndarray:
        """(geometry vertices,) the scalp's hair density (0 where none grows)."""
        density = np.zeros(len(self.neutral), np.float32)
        if self.scalp is not None:
            density[self.scalp.binding.ref[:, 0]] = self.scalp.shade
        return density

    def proxy_draws(self, positions: np.ndarray) -> list:
        """This frame's :class:`facsim.render.proxies.ProxyDraw` s for geometry ``positions``."""
        from facsim.render.proxies import ProxyDraw

        pigment, white, grey = self._hair_greying
        return [ProxyDraw(mesh, self._proxy_positions(bound, positions), tuple(self.colors[bound.color_key]), bound.sheen,
                          bound.density, bound.coil,
                          *((pigment, white, grey) if bound.color_key == "hair" else (None, None, 0.0)))
                for bound, mesh in zip(self._drawn_proxies, self.proxy_meshes)]

    @cached_property
    def _hair_greying(self) -> tuple:
        """Greying scalp hair's strand colours (:func:`facsim.head.proxies.hair_greying`)."""
        from facsim.head.appearance import GREY_HAIR, character_colors
        from facsim.head.colour import hex_to_rgb
        from facsim.head.proxies import hair_greying

        young = character_colors(self.character.with_(age=min(self.character.age, 40.0)))["hair"]
        return hair_greying(self.colors["hair"], young, hex_to_rgb(GREY_HAIR))

    def _proxy_positions(self, bound, positions: np.ndarray) -> np.ndarray:
        """A proxy's vertices on geometry ``positions``; lashes turn with their lids."""
        if bound.proxy.kind != "eyelashes":
            return bound.binding.positions(positions)
        from facsim.engines.checks import head_rotation
        from facsim.engines.lids import lashes_turned_with_lids

        roots, eye_of, vectors = self._lash_roots[id(bound)]
        p = np.asarray(positions)
        eyes = list(self.head.eye_vertices.values())
        centres = np.array([p[v].mean(axis=0) for v in eyes])[eye_of]
        rest_centres = np.array([self.neutral[v].mean(axis=0) for v in eyes])[eye_of]
        rotation = head_rotation(self.neutral[self._skull], p[self._skull])
        return lashes_turned_with_lids(p[roots], self.neutral[roots], vectors, centres, rest_centres, rotation)

    @cached_property
    def _lash_roots(self) -> dict:
        """id(lash proxy) -> (roots, eye index, root-to-vertex vectors) of its vertices on the
        neutral face: each vertex's root is the nearest lid-margin vertex."""
        from scipy.spatial import cKDTree

        margins = [np.concatenate([upper, lower]) for _, upper, lower in self._lid_margins.values()]
        every = np.concatenate(margins)
        margin_eye = np.repeat(np.arange(len(margins)), [len(m) for m in margins])
        tree = cKDTree(self.neutral[every])
        roots = {}
        for bound in self.proxies:
            if bound.proxy.kind == "eyelashes":
                rest = bound.binding.positions(self.neutral)
                nearest = tree.query(rest)[1]
                root = every[nearest]
                roots[id(bound)] = (root, margin_eye[nearest], (rest - self.neutral[root]).astype(np.float64))
        return roots

    @cached_property
    def _skull(self) -> np.ndarray:
        """Skin vertices that only the head's own motion moves (the scalp, well above the
        brows), for its rotation (:func:`facsim.engines.checks.head_rotation`)."""
        skin = np.asarray(self.neutral)[: self.head.skin_vertex_count]
        top = np.flatnonzero(skin[:, 1] > skin[:, 1].max() - 0.6)
        return top[:: max(1, len(top) // 400)]

    @cached_property
    def colors(self) -> dict:
        """The character's sRGB colours, hair included (:func:`facsim.head.appearance.character_colors`)."""
        from facsim.head.appearance import character_colors

        return character_colors(self.character)

    @cached_property
    def appearance(self):
        from facsim.head.appearance import character_appearance

        brows = any(p.proxy.kind == "eyebrows" for p in self.proxies)
        return character_appearance(self.character, self.head, painted_brows=not brows)

    @cached_property
    def topology(self):
        """What the renderer draws of the head: hm08's lash strips give way to a lash proxy,
        and the teeth get coordinates for separate crowns and gums."""
        from facsim.head.mesh import REGIONS, RenderTopology
        from facsim.head.mouth import cavity_coordinates, teeth_coordinates, tongue_coordinates

        topo = self.head.topology
        faces = topo.faces
        if any(p.proxy.kind == "eyelashes" for p in self.proxies):
            faces = faces[topo.face_regions() != REGIONS.index("lashes")]
        # Teeth and tongue have no skin UVs: give the teeth (arc length from the midline,
        # root-ward height), which their shader turns into separate crowns and gums, and the
        # tongue (across, along), for its groove, papillae and fall-off toward the throat.
        uv = np.array(topo.uv, copy=True)
        for region, coordinates in (("teeth", teeth_coordinates), ("tongue", tongue_coordinates)):
            coords = coordinates(self.head, self.data, self.base_positions)
            on = np.flatnonzero(topo.region == REGIONS.index(region))
            uv[on] = coords[topo.render_to_geo[on]]
        # The lining keeps its skin UVs (the paint's mucosa); its place in the mouth (across,
        # up the back wall, depth), for the throat's opening and the uvula, rides in the eyes'
        # slot, which only the eyeballs read otherwise.
        eye_coord = np.array(topo.eye_coord, copy=True)
        on = np.flatnonzero(topo.region == REGIONS.index("mouth_interior"))
        eye_coord[on] = cavity_coordinates(self.head, self.neutral)[topo.render_to_geo[on]]
        return RenderTopology(faces=faces, render_to_geo=topo.render_to_geo, uv=uv,
                              region=topo.region, eye_coord=eye_coord)

    @cached_property
    def shading_occlusion(self) -> np.ndarray:
        """:attr:`occlusion` with contact shadows in the skin's small folds, the skin under the hair
        shadowed by it and the mouth darkening with depth."""
        from facsim.head.mouth import mouth_depth_visibility
        from facsim.head.proxies import hair_shadow
        from facsim.head.skin import CONTACT_DEPTH, contact_shadow

        occlusion = np.array(self.occlusion, np.float32, copy=True)
        skin = self.head.skin
        # Contact shadows in folds too narrow for the bake, placed on the base mesh's anatomy.
        occlusion[skin] *= 1.0 - CONTACT_DEPTH * contact_shadow(self.head.base_vertices[self.head.base_index[skin]])
        interior, visibility = mouth_depth_visibility(self.head, self.neutral)
        occlusion[interior] = visibility
        cover = self._scalp_density
        for bound in self.proxies:
            if bound.proxy.kind == "hair" and not bound.crop:  # a crop's cards are not there
                hair = bound.binding.positions(self.neutral)
                occlusion[skin] *= hair_shadow(self.neutral[skin], hair, cover=cover[skin],
                                               triangles=bound.proxy.corner_vertex[bound.proxy.triangles])
        return occlusion

    def frame_occlusion(self, positions: np.ndarray) -> np.ndarray:
        """:attr:`shading_occlusion` with the upper lids' creases deepened or smoothed where
        ``positions`` put the lids (the lids' shade on the eyeballs comes from :meth:`frame_lids`),
        and the mouth lit by where the lips are (:func:`facsim.head.mouth.mouth_light`)."""
        from facsim.head.mouth import mouth_light
        from facsim.render.geometry import lid_crease_shade

        occlusion = np.array(self.shading_occlusion, np.float32, copy=True)
        positions = self._in_head_frame(positions)
        for side, (centre, upper, _) in self._lid_margins.items():
            crease, weights, height = self._lid_creases[side]
            occlusion[crease] *= lid_crease_shade(positions, centre, crease, weights, upper, height)
        mouth_light(self._mouth_rim, positions, occlusion)
        return occlusion

    def frame_lids(self, positions: np.ndarray) -> np.ndarray:
        """(N_geo, 2) degrees of arc below the upper lid's margin and above the lower's of each
        eyeball vertex where ``positions`` put the lids (90 elsewhere): the renderer's ``lids``."""
        from facsim.render.geometry import lid_elevations

        lids = np.full((len(positions), 2), 90.0, np.float32)
        p = self._in_head_frame(positions)
        for side, (centre, upper, lower) in self._lid_margins.items():
            # Only the eyeball's front can show between the lids (at any gaze 61-64 give).
            eye = self.head.eye_vertices[side][self.head.eye_local[:, 2] > -0.1]
            lids[eye] = lid_elevations(p, centre, eye, upper, lower)
        return lids

    def _in_head_frame(self, positions: np.ndarray) -> np.ndarray:
        """``positions`` with the head's own turn (51-58) undone, so angles about the eyes
        are measured as on the neutral head (elevations are about its up axis)."""
        from facsim.engines.checks import head_rotation

        p = np.asarray(positions, np.float64)
        skull = self._skull
        rotation = head_rotation(self.neutral[skull].astype(np.float64), p[skull])
        if np.allclose(rotation, np.eye(3), atol=1e-6):
            return np.asarray(positions)
        now, rest = p[skull].mean(axis=0), self.neutral[skull].astype(np.float64).mean(axis=0)
        return ((p - now) @ rotation + rest).astype(np.float32)

    @cached_property
    def _mouth_rim(self):
        from facsim.head.mouth import mouth_rim

        return mouth_rim(self.head, self.data, self.neutral)

    @cached_property
    def _lid_creases(self) -> dict:
        """Side -> (crease skin vertices, weights, their rest height above the margin)."""
        from facsim.render.geometry import _height_above, lid_crease_weights

        out = {}
        skin = np.arange(self.head.skin_vertex_count)
        for side, (centre, upper, _) in self._lid_margins.items():
            radius = self.head.eye_pivot(self.base_positions, side)[1]
            crease, weights = lid_crease_weights(self.neutral, centre, skin, upper, radius)
            out[side] = (crease, weights, _height_above(np.asarray(self.neutral), centre, crease, upper))
        return out

    @cached_property
    def _lid_margins(self) -> dict:
        """Side -> (eye centre, upper, lower lid-margin skin vertices) (the lashes' roots), told
        apart at rest: a margin vertex above the line between the eye's corners is the upper lid's."""
        from facsim.engines.lids import lid_margin, spherical

        out = {}
        for side in self.head.eye_vertices:
            centre, radius = self.head.eye_pivot(self.base_positions, side)
            margin = lid_margin(self.head, self.neutral, centre, radius)
            lam, phi = spherical(self.neutral[margin].astype(float), centre)
            a, b = np.argmin(lam), np.argmax(lam)
            corners = np.interp(lam, [lam[a], lam[b]], [phi[a], phi[b]])
            out[side] = (centre, margin[phi > corners], margin[phi < corners])
        return out

    @cached_property
    def occlusion(self) -> np.ndarray:
        """Ambient visibility per vertex (1 open … 0 enclosed), baked once on the neutral face.

        Sockets and creases change little with expression, so one bake per
        character serves every frame; it is cached on disk by the character's parameters.
        """
        import hashlib

        from facsim.head.assets import cache_dir, cached_array
        from facsim.render.occlusion import bake_occlusion

        shape = self.character.with_(name="", description="", colors={}, hair="", brows="", lashes="")
        key = hashlib.sha256(repr((OCCLUSION_VERSION, shape))
                             .encode()).hexdigest()[:16]
        return cached_array(cache_dir() / "occlusion" / f"{key}.npy",
                            lambda: bake_occlusion(self.head.topology, self.neutral))

    def activations(self, expression=None) -> Activations:
        """Activations from a FACS string (read with this face's ``intensities``), an Expression or Activations."""
        return to_activations(expression, intensities=self.intensities)

    def deform(self, expression=None) -> Deformation:
        """The face showing ``expression`` (FACS string, Expression or Activations), reached from neutral."""
        act = self.activations(expression)
        return self.engine.deform(act) if act else Deformation(self.neutral)

    def camera(self, *, view: str = "front", yaw=None, pitch=None, projection="perspective", size=(512, 512), fov_deg=None):
        """A camera framing this character's neutral head and upper neck (the same for every frame)."""
        options = RenderOptions(view=view, yaw=yaw, pitch=pitch, projection=projection, size=size)
        return self._camera(options.view, options.yaw, options.pitch, options.projection, options.size, fov_deg)

    @lru_cache(maxsize=16)  # noqa: B019 — a Face lives as long as its renders
    def _camera(self, view, yaw, pitch, projection, size, fov_deg):
        from facsim.render.camera import DEFAULT_FOV_DEG, frame_points

        skin = self.neutral[self.head.skin]
        chin = float(self.head.joint(self.base_positions, "joint-jaw")[1])
        keep = skin[:, 1] > chin - NECK_SHOWN
        width, height = size
        return frame_points(skin[keep], view=view, yaw=yaw, pitch=pitch, projection=projection,
                            fov_deg=fov_deg or DEFAULT_FOV_DEG, margin=0.06, aspect=width / height)

    def body_rig(self, style: str):
        """This character's body dressed in ``style`` (:class:`facsim.head.body.BodyRig`), or None for ``"none"``."""
        from facsim.head.body import NO_BODY, check_body_style

        if check_body_style(style) == NO_BODY:
            return None
        if style not in self._body_rigs:
            from facsim.head.body import body_base_positions, load_body_data, rig_body

            positions = body_base_positions(self.character, self.data, load_body_data(), self.base_positions)
            self._body_rigs[style] = rig_body(load_body(style), positions, self.neutral)
        return self._body_rigs[style]

    def render_topology(self, body: str = DEFAULT_BODY):
        """What the renderer draws: :attr:`topology`, and with a ``body`` the neck, shoulders and
        garment appended (the neck cap, which they hide, left out so the neck's normals join them)."""
        from facsim.head.mesh import RenderTopology

        rig = self.body_rig(body)
        topo = self.topology
        if rig is None:
            return topo
        faces, render_to_geo, uv, region = rig.model.render_topology()
        head_faces = topo.faces[~(topo.render_to_geo[topo.faces] == self.head.cap_vertex).any(axis=1)]
        return RenderTopology(
            faces=np.concatenate([head_faces, faces + topo.n_render]),
            render_to_geo=np.concatenate([topo.render_to_geo, render_to_geo]),
            uv=np.concatenate([topo.uv, uv]), region=np.concatenate([topo.region, region]),
            eye_coord=np.concatenate([topo.eye_coord, np.zeros((len(uv), 3), np.float32)]))

    def renderer(self, options: RenderOptions | None = None, **option_values):
        """A renderer for this head (cached per size, anti-aliasing, background and body)."""
        from facsim.render.renderer import Renderer

        options = _options(options, option_values)
        key = (options.size, options.antialias, options.background, options.body, options.shadows)
        if key not in self._renderers:
            self._renderers[key] = Renderer(self.render_topology(options.body), size=options.size,
                                            background=options.background, **options.renderer_settings())
        return self._renderers[key]

    def render(self, expression=None, *, options: RenderOptions | None = None, deformation: Deformation | None = None,
               positions=None, wrinkle=None, crease_phase=None, **option_values) -> np.ndarray:
        """Render ``expression`` to an (H, W, 4) uint8 RGBA image.

        Options are a :class:`RenderOptions` or its fields as keywords (view,
        yaw, pitch, size, projection, background — None for transparent —,
        antialias). ``deformation`` renders a given :class:`Deformation` (e.g.
        an animation frame) instead of deforming; ``positions`` (with its
        ``wrinkle`` and ``crease_phase``) renders raw geometry.
        """
        options = _options(options, option_values)
        if positions is not None:
            deformation = Deformation(np.asarray(positions, np.float32),
                                      creases=None if wrinkle is None else (lambda: (wrinkle, crease_phase)))
        elif deformation is None:
            deformation = self.deform(expression)
        camera = self.camera(view=options.view, yaw=options.yaw, pitch=options.pitch, projection=options.projection,
                             size=options.size)
        positions = np.asarray(deformation.positions, np.float32)
        wrinkle, crease_phase = deformation.wrinkle, deformation.crease_phase
        occlusion, lids = self.frame_occlusion(positions), self.frame_lids(positions)
        proxies = self.proxy_draws(positions)
        rig = self.body_rig(options.body)
        if rig is not None:  # the body's rows after the head's: still skin and cloth, open, no lids
            positions = rig.with_body(positions)
            rows = rig.model.row_count

            def extend(values, fill):
                return None if values is None else np.concatenate(
                    [np.asarray(values, np.float32), np.full((rows, *np.shape(values)[1:]), fill, np.float32)])
            wrinkle, crease_phase, lids = extend(wrinkle, 0.0), extend(crease_phase, 0.0), extend(lids, 90.0)
            occlusion = np.concatenate([occlusion, rig.occlusion])
        return self.renderer(options).render(
            positions, appearance=self.appearance, camera=camera, wrinkle=wrinkle, crease_phase=crease_phase,
            occlusion=occlusion, lids=lids, proxies=proxies,
        )

    def start_animation(self) -> Engine:
        """The engine, back at the neutral face: call ``.step(activations)`` per frame for :class:`Deformation` s."""
        self.engine.reset()
        return self.engine

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


def _options(options: RenderOptions | None, values: dict) -> RenderOptions:
    """One RenderOptions from an object and/or keyword values (keywords override)."""
    if options is None:
        return RenderOptions(**values)
    return options.replace(**values) if values else options
