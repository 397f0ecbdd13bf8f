"""Wrinkles, furrows and bulges from skin compression (placeholder, replaced below)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class WrinkleModel:
    rest: np.ndarray
    triangles: np.ndarray


def build_wrinkles(anat, net, spec) -> WrinkleModel:
    return WrinkleModel(net.rest, net.triangles)


def wrinkle_field(model: WrinkleModel, skin: np.ndarray) -> np.ndarray:
    return np.zeros(len(skin), np.float32)
