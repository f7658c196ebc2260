"""Coercion of user input to floats, with errors that name the argument.

Only real numbers are accepted: bools, strings, bytes, complex numbers,
mappings and sets are refused by name rather than read as numbers (a string
``'12'`` is not the point (1, 2), a dict is not its keys). Masked arrays are
refused too: numpy drops the mask on conversion, so a masked value would be
solved as whatever number lies under it. Messages show values as plain
Python numbers (``shown``), never numpy reprs.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping, Set
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

__all__ = ["as_float", "as_point", "as_points", "as_real_array", "as_unit", "as_xy", "per_item", "shown"]

#: Array dtype kinds that hold real numbers (signed, unsigned, floating).
_REAL_KINDS = "iuf"


def _refused(value: Any) -> bool:
    """Values that Python or numpy would turn into numbers but that are not real numbers."""
    return isinstance(value, (bool, np.bool_, str, bytes, complex, np.complexfloating, Mapping, Set)) or value is None


def shown(value: Any) -> str:
    """``repr`` of ``value`` with numpy scalars and arrays as plain Python values (for messages)."""
    if isinstance(value, (np.generic, np.ndarray)) and not isinstance(value, np.ma.MaskedArray):
        value = value.tolist()
    elif isinstance(value, tuple):
        return "(" + ", ".join(shown(v) for v in value) + ("," if len(value) == 1 else "") + ")"
    elif isinstance(value, list):
        return "[" + ", ".join(shown(v) for v in value) + "]"
    return repr(value)


def _refuse_masked(value: Any, name: str) -> None:
    """ValueError naming ``name`` for a masked array (or a sequence holding one)."""
    masked = isinstance(value, np.ma.MaskedArray) or (
        isinstance(value, (list, tuple)) and any(isinstance(v, np.ma.MaskedArray) for v in value)
    )
    if masked:
        raise ValueError(
            f"{name} is a masked array: masked values have no geometry; fill them (np.ma.filled) or drop "
            "those rows (np.ma.compress_rows) first"
        )


def as_float(value: Any, name: str) -> float:
    """``value`` as a finite float, else ValueError naming ``name``."""
    if type(value) is float or type(value) is int:  # the common case, checked cheaply
        try:
            number = float(value)
        except OverflowError:
            number = math.inf
        if math.isfinite(number):
            return number
    _refuse_masked(value, name)
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in _REAL_KINDS:
        value = value[()]
    if _refused(value) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} must be a real number; got {type(value).__name__} {shown(value):.80}")
    try:
        number = float(value)
    except OverflowError:
        raise ValueError(f"{name} is too large for float64; got {shown(value):.80}") from None
    if not math.isfinite(number):
        raise ValueError(f"{name} must be finite; got {number}")
    return number


def as_xy(value: Any, name: str) -> tuple[float, float]:
    """``value`` (a 2-sequence, or a 3-vector with z = 0) as two finite floats."""
    if (type(value) is tuple or type(value) is list) and len(value) == 2:  # the common cases, checked cheaply
        x, y = value
        if type(x) is float and type(y) is float and math.isfinite(x) and math.isfinite(y):
            return x, y
        if (type(x) is float or type(x) is int) and (type(y) is float or type(y) is int):
            try:
                x, y = float(x), float(y)
            except OverflowError:  # an int beyond float64: named below
                pass
            else:
                if math.isfinite(x) and math.isfinite(y):
                    return x, y
    elif type(value) is np.ndarray and value.shape == (2,) and value.dtype == np.float64:
        x, y = value.tolist()
        if math.isfinite(x) and math.isfinite(y):
            return x, y
    return cast(tuple[float, float], as_point(value, name, plane_only=True))  # plane_only: two coordinates


def as_point(value: Any, name: str, plane_only: bool = False) -> tuple[float, ...]:
    """``value`` as a plane point (x, y) or a point in space (x, y, z), finite floats.

    A 3-D point with z = 0 is the plane point (x, y), as for every plane input;
    ``plane_only`` refuses the rest.
    """
    if not plane_only and ((type(value) is tuple and len(value) == 2) or (type(value) is np.ndarray and value.shape == (2,))):
        return as_xy(value, name)  # the common case, checked cheaply
    what = "a 2-D point or vector" if plane_only else "a 2-D or 3-D point"
    _refuse_masked(value, name)
    if _refused(value):
        raise ValueError(f"{name} must be {what}; got {type(value).__name__} {shown(value):.80}")
    try:
        items = list(value)
    except TypeError:
        raise ValueError(f"{name} must be {what}; got {type(value).__name__} {shown(value):.80}") from None
    coords = tuple(as_float(c, f"{name}[{i}]") for i, c in enumerate(items))
    if len(coords) == 3 and coords[2] == 0.0:
        coords = coords[:2]
    if len(coords) not in ((2,) if plane_only else (2, 3)):
        raise ValueError(f"{name} must have {'2' if plane_only else '2 or 3'} coordinates; got {shown(value):.80}")
    return coords


def as_unit(value: Any, name: str) -> tuple[float, float]:
    """A non-zero 2-vector normalised to unit length (``math.hypot`` neither overflows nor underflows)."""
    x, y = as_xy(value, name)
    length = math.hypot(x, y)
    if length == 0.0:
        raise ValueError(f"{name} must be a non-zero vector; got ({x}, {y})")
    return x / length, y / length


def as_real_array(value: Any, name: str) -> NDArray[np.float64]:
    """``value`` as a float64 array of real numbers (no bools, strings, complex or objects that are not numbers)."""
    _refuse_masked(value, name)
    if _refused(value):
        raise ValueError(f"{name} must be an array of real numbers; got {type(value).__name__} {shown(value):.80}")
    try:
        array = np.asarray(value)
    except ValueError as error:  # ragged nesting
        raise ValueError(f"{name} must be a rectangular array of real numbers: {error}") from None
    if array.dtype.kind == "O":
        flat = array.ravel()
        bad = next((v for v in flat if _refused(v) or not isinstance(v, numbers.Real)), None)
        if bad is not None:
            raise ValueError(f"{name} must hold real numbers only; got {type(bad).__name__} {shown(bad):.80}")
        try:
            return array.astype(np.float64)
        except (OverflowError, ValueError):
            raise ValueError(f"{name} holds a number too large for float64") from None
    if array.dtype.kind not in _REAL_KINDS:
        raise ValueError(f"{name} must hold real numbers; got an array of {array.dtype} ({array.dtype.kind!r})")
    return array.astype(np.float64, copy=False)


def as_points(value: Any, name: str, shape: tuple[int, ...] = (2,)) -> NDArray[np.float64]:
    """``value`` as a float64 array whose trailing shape is ``shape``."""
    array = as_real_array(value, name)
    if array.shape[array.ndim - len(shape) :] != shape:
        raise ValueError(f"{name} must have trailing shape {shape}; got {array.shape}")
    return array


def per_item(value: Any, count: int, name: str, item: str) -> NDArray[np.float64]:
    """``value`` as ``count`` finite floats: one number for all, or one per ``item`` (named in the error)."""
    array = as_real_array(value, name)
    if array.ndim == 0:
        array = np.full(count, float(array))
    if array.shape != (count,):
        raise ValueError(f"{name} needs one value or one per {item} ({count}); got shape {array.shape}")
    if not np.isfinite(array).all():
        raise ValueError(f"{name} must be finite; got {array.tolist()}")
    return array
