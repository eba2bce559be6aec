"""What a render tells its caller besides the image: progress while it
runs (``progress=``) and the optics it chose (``chosen=True``)."""

from __future__ import annotations

import sys
import time
from typing import Any, Callable, Dict, Iterator, Mapping, Optional, Union

ProgressCallback = Callable[[int, int], Any]
"""``progress(done, total)``: units of work (photons, rays or tiles) done
so far of the render's total, called on the caller's thread."""


class _Bar:
    """A one-line progress bar on stderr, like PyVista's ``progress_bar``."""

    WIDTH = 24

    def __init__(self, what: str) -> None:
        self.what = what
        self.start = time.monotonic()
        self.shown = -1

    def __call__(self, done: int, total: int) -> None:
        fraction = done / total if total else 1.0
        percent = int(100 * fraction)
        if percent == self.shown and done < total:
            return
        self.shown = percent
        filled = int(self.WIDTH * fraction)
        bar = "█" * filled + " " * (self.WIDTH - filled)
        took = time.monotonic() - self.start
        end = "\n" if done >= total else ""
        sys.stderr.write(f"\r{self.what} {percent:3d}% |{bar}| {took:.1f} s{end}")
        sys.stderr.flush()


def _progress(progress: Union[None, bool, ProgressCallback], what: str) -> Optional[ProgressCallback]:
    """The callback for ``progress=``: None or False (none), True (a bar
    on stderr named ``what``) or the caller's own ``callable(done, total)``."""
    if progress is None or progress is False:
        return None
    if progress is True:
        return _Bar(what)
    if not callable(progress):
        raise TypeError(f"progress: expected True, False, None or a callable(done, total), got {type(progress).__name__}")
    return progress


class Optics(Mapping[str, Any]):
    """The optics a render used, its automatic choices made explicit, by
    the keyword names of the function that rendered it: pass it back as
    ``**chosen`` to repeat them, e.g. on every time step of a simulation
    (automatic exposure, chosen per call, would flicker)::

        img, chosen = rtvis.schlieren(vol_t0, chosen=True)
        frames = [rtvis.schlieren(v, **chosen) for v in series]

    A read-only mapping; fields are attributes too (``chosen.h``);
    ``description`` is the one-line summary ``rt`` prints."""

    def __init__(self, description: str, **fields: Any) -> None:
        self._fields: Dict[str, Any] = dict(fields)
        self.description = description

    def __getitem__(self, key: str) -> Any:
        return self._fields[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._fields)

    def __len__(self) -> int:
        return len(self._fields)

    def __getattr__(self, key: str) -> Any:
        try:
            return self.__dict__["_fields"][key]
        except KeyError:
            raise AttributeError(f"Optics has no field {key!r} (fields: {', '.join(self._fields)})") from None

    def __repr__(self) -> str:
        return "Optics(" + ", ".join(f"{k}={v!r}" for k, v in self._fields.items()) + ")"
