"""The baked table: one object that writers and checks see."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .axes import Axis


@dataclass
class Table:
    """``data`` has shape (y, x, channels) for 2D kinds, (z, y, x, channels) for 3D kinds:
    the axes list follows the array's dimensions in order (slowest first), the channel axis last."""

    name: str
    kind: str
    data: np.ndarray
    axes: list[Axis]
    channels: dict[str, str]
    reconstruction: str
    attributes: dict[str, str] = field(default_factory=dict)  # provenance, written as lutbake:*

    @property
    def shape(self) -> tuple[int, ...]:
        return self.data.shape

    def channel(self, key: str) -> np.ndarray:
        return self.data[..., list(self.channels).index(key)]
