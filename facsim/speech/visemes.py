"""The viseme table (``facsim/data/visemes.yaml``): phones → visemes → FACS AUs.

Examples
--------
>>> table = viseme_table()
>>> table.viseme_of("b").name, table.viseme_of("b").aus[24]
('PP', 0.7)
>>> sorted(table.viseme_of("uw").aus)
[18, 22, 26]
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from types import MappingProxyType
from typing import Mapping

import yaml

from .utterance import SILENCE

DATA_FILE = "data/visemes.yaml"


@dataclass(frozen=True)
class Constraint:
    """A JALI-style rule over the middle of a phone: ``suppress`` AUs → 0, ``hold`` AUs ≥ target."""

    suppress: tuple[int, ...] = ()
    hold: tuple[int, ...] = ()


@dataclass(frozen=True)
class Viseme:
    """One mouth shape: the phones it shows, its AU targets and how strongly it holds them."""

    name: str
    phones: tuple[str, ...]
    aus: Mapping[int, float]
    dominance: float
    reason: str
    constraint: Constraint | None = None


@dataclass(frozen=True)
class Coarticulation:
    """Cohen–Massaro dominance settings (see the YAML file's comments)."""

    rate_before: float
    rate_after: float
    rest_pause: float
    short_pause_dominance: float
    constraint_share: float
    constraint_ramp: float


@dataclass(frozen=True)
class VisemeTable:
    visemes: Mapping[str, Viseme]
    coarticulation: Coarticulation
    speech_owns: frozenset[int]
    _by_phone: Mapping[str, Viseme] = field(repr=False)

    @property
    def codes(self) -> tuple[int, ...]:
        """Every AU code any viseme or constraint uses, sorted."""
        codes = set()
        for v in self.visemes.values():
            codes |= set(v.aus)
            if v.constraint:
                codes |= set(v.constraint.suppress) | set(v.constraint.hold)
        return tuple(sorted(codes))

    @property
    def phones(self) -> tuple[str, ...]:
        return tuple(sorted(self._by_phone))

    def viseme_of(self, phone: str) -> Viseme:
        """The viseme showing ``phone`` (ARPAbet, lower case); unknown phones look like silence."""
        return self._by_phone.get(phone) or self._by_phone[SILENCE]


def _problem(where: str, text: str) -> ValueError:
    return ValueError(f"{DATA_FILE}: {where}: {text}")


@lru_cache(maxsize=1)
def viseme_table() -> VisemeTable:
    """The table, read and checked once."""
    from facsim.facs.catalogue import info

    raw = yaml.safe_load(resources.files("facsim").joinpath(DATA_FILE).read_text())
    co = Coarticulation(**{k: float(v) for k, v in raw["coarticulation"].items()})
    visemes, by_phone = {}, {}
    for name, row in raw["visemes"].items():
        aus = {}
        for code, level in (row.get("aus") or {}).items():
            info(int(code))  # raises for a code that is not in the catalogue
            if not 0.0 <= float(level) <= 1.0:
                raise _problem(f"visemes.{name}.aus.{code}", f"intensity must be in 0..1, got {level}")
            aus[int(code)] = float(level)
        constraint = None
        if row.get("constraint"):
            c = row["constraint"]
            constraint = Constraint(tuple(int(x) for x in c.get("suppress") or ()),
                                    tuple(int(x) for x in c.get("hold") or ()))
        viseme = Viseme(name, tuple(row["phones"]), MappingProxyType(aus), float(row["dominance"]),
                        " ".join(str(row.get("reason", "")).split()), constraint)
        for phone in viseme.phones:
            if phone in by_phone:
                raise _problem(f"visemes.{name}.phones", f"{phone!r} is also in {by_phone[phone].name}")
            by_phone[phone] = viseme
        visemes[name] = viseme
    if SILENCE not in by_phone:
        raise _problem("visemes", f"no viseme lists the silence phone {SILENCE!r}")
    return VisemeTable(MappingProxyType(visemes), co, frozenset(int(c) for c in raw["speech_owns"]),
                       MappingProxyType(by_phone))


def describe_visemes() -> str:
    """The table as text (``facsim visemes``)."""
    lines = [f"{'viseme':7s} {'phones':24s} {'AUs':28s} dominance  reason"]
    for v in viseme_table().visemes.values():
        aus = "+".join(f"{c}@{level:g}" for c, level in sorted(v.aus.items())) or "(rest)"
        lines.append(f"{v.name:7s} {' '.join(v.phones):24s} {aus:28s} {v.dominance:9.2f}  {v.reason}")
    return "\n".join(lines)
