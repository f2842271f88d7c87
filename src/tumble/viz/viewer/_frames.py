"""Decimation: which samples of a trajectory become the viewer's frames.

A run of ``n`` samples is shown as at most ``frames`` of them (the *frame
budget*, default :data:`DEFAULT_FRAMES`), evenly spaced in sample index and
always including the first and the last sample, so that a long run still
gives a small file (the size of the page grows linearly with the frames;
``docs/viewer.md`` gives sizes). The frames are samples of the trajectory,
never interpolated: each frame shows the state at its sample time exactly.
"""

from __future__ import annotations

import operator

import numpy as np

from tumble._validate import ValidationError

__all__ = ["DEFAULT_FRAMES", "MAX_FRAMES", "check_budget", "frame_indices"]

#: Frames of a page when not said otherwise.
DEFAULT_FRAMES = 600
#: The largest frame budget: a free rigid body's page grows by some 760 bytes a frame and takes some 5 kB a
#: frame of memory while it is built, so 100 000 frames make a page of about 80 MB (0.5 GB to build), more
#: than a browser animates; a larger budget on a long run would grow the page without bound.
MAX_FRAMES = 100_000


def check_budget(frames) -> int:
    """``frames`` as an int, refused unless it is a whole number from 2 (a first and a last frame) to
    :data:`MAX_FRAMES`."""
    try:
        budget = operator.index(frames)
    except TypeError:
        raise ValidationError(f"frames: must be a whole number >= 2 (the frame budget), got {frames!r}") from None
    if budget < 2:
        raise ValidationError(f"frames: must be >= 2 (a first and a last frame), got {budget}")
    if budget > MAX_FRAMES:
        raise ValidationError(f"frames: must be at most {MAX_FRAMES} (a page of about 80 MB; a browser "
                              f"animates no more), got {budget}")
    return budget


def frame_indices(n: int, frames: int) -> np.ndarray:
    """Indices (m,) of the samples shown, ``m = min(n, frames)``: ``round(k (n − 1)/(m − 1))``, k = 0 … m − 1."""
    budget = check_budget(frames)
    if n <= budget:
        return np.arange(n)
    return np.round(np.linspace(0.0, n - 1.0, budget)).astype(np.int64)
