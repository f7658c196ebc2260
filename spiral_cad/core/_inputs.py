"""Coercion of user input to floats, with errors that name the argument."""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def as_float(value: Any, name: str) -> float:
    """``value`` as a finite float, else ValueError naming ``name``."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number; got {value!r}") from None
    if not math.isfinite(number):
        raise ValueError(f"{name} must be finite; got {number}")
    return number


def as_xy(value: Any, name: str) -> tuple[float, float]:
    """``value`` (any 2-sequence, or a 3-vector with z = 0) as two finite floats."""
    try:
        coords = [float(c) for c in value]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a 2-D point or vector; got {value!r}") from None
    if len(coords) == 3 and coords[2] == 0.0:
        coords = coords[:2]
    if len(coords) != 2:
        raise ValueError(f"{name} must have 2 coordinates; got {value!r}")
    if not (math.isfinite(coords[0]) and math.isfinite(coords[1])):
        raise ValueError(f"{name} must be finite; got {tuple(coords)}")
    return coords[0], coords[1]


def as_unit(value: Any, name: str) -> tuple[float, float]:
    """A non-zero 2-vector normalised to unit length."""
    x, y = as_xy(value, name)
    length = math.hypot(x, y)
    if length == 0.0:
        raise ValueError(f"{name} must be a non-zero vector; got ({x}, {y})")
    return x / length, y / length


def as_points(value: Any, name: str, shape: tuple[int, ...] = (2,)) -> np.ndarray:
    """``value`` as a float64 array whose trailing shape is ``shape``."""
    array = np.asarray(value, dtype=float)
    if array.shape[array.ndim - len(shape) :] != shape:
        raise ValueError(f"{name} must have trailing shape {shape}; got {array.shape}")
    return array
