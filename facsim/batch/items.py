"""A :class:`~facsim.batch.spec.StimulusSet` → the deterministic list of files to make.

:func:`expand` is a pure function: the same set gives the same items, in the
same order, with the same names, on every machine. Each :class:`Item` is one
output file and carries everything needed to render it (no file to read), so
it can travel to a process pool or a Dask worker as it is.

Design
------
A *condition* is one stimulus × intensity × engine × view × size of a block.
Counterbalancing decides which characters show which conditions:

* ``full``: every character shows every condition (each identity each
  condition once, so equally often);
* ``latin_square``: the block's conditions, in a seeded random order, are
  dealt to the characters in turn, so each character shows ⌊C/n⌋ or ⌈C/n⌉ of
  the block's C conditions; list *k* (of ``lists``) shifts the rotation by
  *k*, so over the lists every condition is shown by ``lists`` different
  characters, and with ``lists`` = n each condition by every character once.
  The rotation runs on from one block to the next, so over the whole set
  too the characters' counts differ by at most one.

Every condition then becomes its outputs: one PNG per still level (level ×
the condition's intensity), a video, a glb. Names are *readable*
(``block/character/AU12L_i100.mp4``) or *blind*: seeded random tokens
(``stimuli/k3x9qv2m7d.mp4``) with the labels only in the key file.

Examples
--------
>>> from facsim.batch.spec import spec_from_dict
>>> s = spec_from_dict({"characters": ["ava", "liam"], "blocks": [
...     {"name": "au", "aus": [1, 12], "outputs": {"stills": [0.3, 0.9], "video": True}}]})
>>> items = expand(s)
>>> len(items), items[0].file, items[0].intensity
(12, 'au/ava/AU01_i030.png', 0.3)
"""
from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from typing import Iterator

import numpy as np

from facsim.render.options import DEFAULT_BODY

from .spec import Block, SpecError, Stimulus, StimulusSet, VideoOutput

#: Letters for blind names: no 0/o, 1/l; 10 of them give ~2**48 names.
BLIND_ALPHABET = "abcdefghijkmnpqrstuvwxyz23456789"
BLIND_LENGTH = 10
KINDS = ("still", "video", "glb")


@dataclass(frozen=True)
class Condition:
    """One cell of a block's design, before a character is given to it."""

    block: str
    stimulus: Stimulus
    intensity: float
    engine: str
    view: str
    size: tuple[int, int]


@dataclass(frozen=True)
class Item:
    """One output file: what it shows and how to make it.

    ``key`` is the readable name, unique in the set whatever the naming style
    (the journal and resume go by it); ``file`` is the path in the output
    folder. ``intensity`` is the level shown (a still's level, a video's peak);
    ``peak`` the condition's intensity. Videos run ``onset``/``apex``/
    ``offset`` at ``fps`` (timelines: their own timing; ``duration`` is the
    length either way, 0 for stills).
    """

    key: str
    file: str
    kind: str
    block: str
    list: int
    character: str
    engine: str
    view: str
    width: int
    height: int
    stimulus: Stimulus
    intensity: float
    peak: float
    aus: tuple[int, ...]
    duration: float = 0.0
    fps: float = 0.0
    onset: float = 0.0
    apex: float = 0.0
    offset: float = 0.0
    easing: str = "linear"
    format: str = "png"
    intensities: str = "hapfacs"
    background: tuple[float, float, float] = (1.0, 1.0, 1.0)
    body: str = DEFAULT_BODY
    antialias: int | str = 4

    @property
    def label(self) -> str:
        return self.stimulus.label


def conditions(block: Block) -> tuple[Condition, ...]:
    """The block's conditions in a fixed order: stimulus, intensity, engine, view, size."""
    return tuple(Condition(block.name, stim, level, engine, view, size)
                 for stim in block.stimuli for level in block.intensities
                 for engine in block.engines for view in block.views for size in block.sizes)


def assignments(block: Block, index: int, *, method: str, lists: int, seed: int, start: int = 0
                ) -> Iterator[tuple[int, str, Condition]]:
    """(list number, character, condition) triples of one block; lists count from 1 (0: no lists).

    ``index`` is the block's position, so blocks draw independent orders from one seed; ``start``
    is where the rotation over the characters begins (the conditions dealt before this block), so
    the remainders of several blocks fall on different characters and the whole set stays balanced.

    Examples
    --------
    >>> from facsim.batch.spec import spec_from_dict
    >>> s = spec_from_dict({"characters": ["ava", "liam", "zola"], "blocks": [
    ...     {"name": "b", "facs": ["1", "2", "4", "12", "15", "26"], "outputs": {"stills": [1]}}]})
    >>> cast = [c for _, c, _ in assignments(s.blocks[0], 0, method="latin_square", lists=1, seed=0)]
    >>> sorted(cast.count(name) for name in ("ava", "liam", "zola"))
    [2, 2, 2]
    """
    conds = conditions(block)
    chars = block.characters
    if method == "full":
        for char in chars:
            for cond in conds:
                yield 0, char, cond
        return
    order = np.random.default_rng([seed, index]).permutation(len(conds))
    for k in range(lists):
        for position, c in enumerate(order):
            yield k + 1, chars[(start + position + k) % len(chars)], conds[int(c)]


def _intensity_tag(level: float) -> str:
    return f"i{int(round(level * 100)):03d}"


def _slug(character: str) -> str:
    return character.replace(":", "-")


def _condition_aus(stim: Stimulus) -> tuple[int, ...]:
    if stim.kind == "au":
        return (stim.au,)
    if stim.kind == "timeline":
        tracks = json.loads(stim.timeline)["tracks"]
        codes: set[int] = set()
        for track in tracks:
            if "au" in track:
                codes.add(track["au"])
            else:
                codes |= _expression_codes(track.get("facs"), track.get("emotion"), track.get("table"))
        return tuple(sorted(codes))
    return tuple(sorted(_expression_codes(stim.facs if stim.kind == "facs" else None, stim.emotion, stim.table)))


def _expression_codes(facs, emotion, table) -> set[int]:
    if emotion is not None:
        from facsim.facs.emotions import emotion as preset

        return set(preset(emotion, **({"table": table} if table else {})).codes)
    from facsim.facs.notation import parse

    return set(parse(facs).codes)


def _items_of(spec: StimulusSet, block: Block, list_no: int, character: str, cond: Condition) -> list[Item]:
    """The condition's output files, readable names (``file`` = ``key``)."""
    stim, (width, height) = cond.stimulus, cond.size
    folder = f"{block.name}/" + (f"list{list_no}/" if spec.lists > 1 else "") + f"{_slug(character)}/"
    extras = "".join(f"_{value}" for value, options in (
        (cond.engine, block.engines), (cond.view, block.views), (f"{width}x{height}", block.sizes))
        if len(options) > 1)
    common = dict(block=block.name, list=list_no, character=character, engine=cond.engine, view=cond.view,
                  width=width, height=height, stimulus=stim, peak=cond.intensity,
                  aus=_condition_aus(stim), intensities=spec.intensities,
                  background=spec.background, body=spec.body, antialias=spec.antialias)
    out = []
    peak_tag = "" if stim.kind == "timeline" else "_" + _intensity_tag(cond.intensity)
    for level in block.outputs.stills:
        shown = round(cond.intensity * level, 12)
        name = f"{folder}{stim.label}_{_intensity_tag(shown)}{extras}.png"
        out.append(Item(key=name, file=name, kind="still", intensity=shown, **common))
    video = block.outputs.video
    timing = {}
    if stim.kind == "timeline":
        from facsim.timeline.io import timeline_from_dict

        timeline = timeline_from_dict(json.loads(stim.timeline))  # its own timing and frame rate
        timing = dict(duration=timeline.length, fps=timeline.fps)
    elif video is not None or block.outputs.glb:  # a glb without a video is animated with the default timing
        v = video if video is not None else VideoOutput()
        timing = dict(duration=v.onset + v.apex + v.offset, fps=v.fps, onset=v.onset, apex=v.apex,
                      offset=v.offset, easing=v.easing)
    if video is not None:
        name = f"{folder}{stim.label}{peak_tag}{extras}.{video.format}"
        out.append(Item(key=name, file=name, kind="video", intensity=cond.intensity, format=video.format,
                        **timing, **common))
    if block.outputs.glb:
        name = f"{folder}{stim.label}{peak_tag}_{cond.engine}.glb" if len(block.engines) > 1 \
            else f"{folder}{stim.label}{peak_tag}.glb"
        # A glb carries the character, its morph targets and the animation: views and sizes do not apply,
        # so it is made once per condition with the first view and size.
        if cond.view == block.views[0] and cond.size == block.sizes[0]:
            out.append(Item(key=name, file=name, kind="glb", intensity=cond.intensity, format="glb",
                            **timing, **common))
    return out


def blind_names(keys: list[str], seed: int) -> dict[str, str]:
    """Seeded random tokens for ``keys`` (in sorted order), distinct, the same for the same keys and seed.

    Examples
    --------
    >>> names = blind_names(["a/x.png", "b/y.mp4"], 7)
    >>> names == blind_names(["b/y.mp4", "a/x.png"], 7), len(set(names.values()))
    (True, 2)
    """
    rng = np.random.default_rng([seed, 0xB11D])
    alphabet = np.array(list(BLIND_ALPHABET))
    taken: set[str] = set()
    names = {}
    for key in sorted(keys):
        while True:
            token = "".join(alphabet[rng.integers(0, len(alphabet), BLIND_LENGTH)])
            if token not in taken:
                break
        taken.add(token)
        names[key] = token
    return names


def expand(spec: StimulusSet) -> tuple[Item, ...]:
    """Every output file of the set, sorted by ``key``; a pure function of ``spec``.

    Raises
    ------
    SpecError
        If two outputs would get the same name (e.g. still levels that meet
        at the same intensity), naming the block.
    """
    items: dict[str, Item] = {}
    dealt = 0
    for index, block in enumerate(spec.blocks):
        for list_no, character, cond in assignments(block, index, method=spec.counterbalance,
                                                    lists=spec.lists, seed=spec.seed, start=dealt):
            for item in _items_of(spec, block, list_no, character, cond):
                if item.key in items:
                    raise SpecError(f"two outputs would both be {item.key!r}; give distinct intensities "
                                    "and still levels (a still's level times the intensity names it)",
                                    location=("blocks", index))
                items[item.key] = item
        dealt += len(conditions(block))
    ordered = [items[k] for k in sorted(items)]
    if spec.naming == "blind":
        tokens = blind_names(list(items), spec.seed)
        ordered = [dataclasses.replace(it, file=f"stimuli/{tokens[it.key]}.{it.format}") for it in ordered]
    return tuple(ordered)


__all__ = ["Condition", "Item", "assignments", "blind_names", "conditions", "expand"]
