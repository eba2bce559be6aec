"""The argument checkers every entry point runs before the native half:
``TypeError`` for the wrong kind of value, ``ValueError`` for the wrong
shape, NaN, out of range or an unknown option."""

from __future__ import annotations

import math
from typing import Any, Literal, Optional, Sequence, Tuple, overload

import numpy as np
from numpy.typing import NDArray


class RtvisWarning(RuntimeWarning):
    """A render that ran, but may not show what you expect: fringes that
    alias, … (``warnings.filterwarnings("error", category=RtvisWarning)``
    makes them errors; Jupyter shows them under the cell)."""


def _choice(name: str, value: Any, known: Sequence[str]) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name}: expected one of {', '.join(known)} (a str), got {type(value).__name__}")
    if value not in known:
        raise ValueError(f"{name}: unknown {value!r} (known: {', '.join(known)})")
    return value


@overload
def _number(name: str, value: Any, *, positive: bool = ..., optional: Literal[False] = ...) -> float: ...
@overload
def _number(name: str, value: Any, *, positive: bool = ..., optional: bool) -> Optional[float]: ...


def _number(name: str, value: Any, *, positive: bool = False, optional: bool = False) -> Optional[float]:
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name}: expected a number, got {type(value).__name__}")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite (got {v})")
    if positive and v <= 0.0:
        raise ValueError(f"{name} must be > 0 (got {v})")
    return v


@overload
def _float(name: str, value: Any, *, optional: Literal[False] = ...) -> float: ...
@overload
def _float(name: str, value: Any, *, optional: bool) -> Optional[float]: ...


def _float(name: str, value: Any, *, optional: bool = False) -> Optional[float]:
    """``value`` as a float, its type checked only: the native half's
    set-ups check ranges (NaN and infinities included), once."""
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name}: expected a number, got {type(value).__name__}")
    return float(value)


def _str(name: str, value: Any) -> str:
    """``value`` as a str, its type checked only (the native half knows
    the names)."""
    if not isinstance(value, str):
        raise TypeError(f"{name}: expected a str, got {type(value).__name__}")
    return value


def _uint(name: str, value: Any, bits: int = 32) -> int:
    """``value`` as an int in the native type's domain; the native half
    checks its range."""
    return _integer(name, value, 0, 2**bits - 1)


def _integer(name: str, value: Any, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name}: expected an int, got {type(value).__name__}")
    v = int(value)
    if not lo <= v <= hi:
        raise ValueError(f"{name} must be {lo} to {hi} (got {v})")
    return v


@overload
def _vector(name: str, value: Any, n: Literal[3] = ...) -> Tuple[float, float, float]: ...
@overload
def _vector(name: str, value: Any, n: Literal[2]) -> Tuple[float, float]: ...
@overload
def _vector(name: str, value: Any, n: int) -> Tuple[float, ...]: ...


def _vector(name: str, value: Any, n: int = 3) -> Tuple[float, ...]:
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected {n} numbers") from None
    if a.shape != (n,):
        raise ValueError(f"{name}: expected {n} numbers, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite (got {tuple(a)})")
    return tuple(float(v) for v in a)


def _array(name: str, value: Any, ndim: int, dtype: Any, *, last: Optional[int] = None, integer: bool = False,
           nan: bool = False) -> NDArray[Any]:
    """``value`` as a C-contiguous array of ``dtype`` (copied if needed),
    its kind and shape checked; NaN allowed with ``nan``, infinities never."""
    if not isinstance(value, np.ndarray):
        try:
            value = np.asarray(value)
        except (TypeError, ValueError):
            raise TypeError(f"{name}: expected an array of numbers") from None
    kinds = "iu" if integer else "fiu"
    if value.dtype.kind not in kinds:
        what = "integers" if integer else "float32 or float64 numbers"
        raise TypeError(f"{name}: expected {what}, got dtype {value.dtype}")
    if value.ndim != ndim or (last is not None and value.shape[-1] != last):
        want = f"{ndim} dimensions" + (f", the last of length {last}" if last is not None else "")
        raise ValueError(f"{name}: expected {want}; got shape {value.shape}")
    if value.size == 0:
        raise ValueError(f"{name} is empty (shape {value.shape})")
    if integer:
        return np.ascontiguousarray(value, dtype=np.int64)
    with np.errstate(over="ignore", invalid="ignore"):  # reported below
        out = np.ascontiguousarray(value, dtype=dtype)
    bad = np.isinf(out) if nan else ~np.isfinite(out)
    if bad.any():
        where = tuple(int(i) for i in np.argwhere(bad)[0])
        raise ValueError(f"{name}: value at {where} is not finite ({out[where]})")
    return out
