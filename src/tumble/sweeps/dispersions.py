"""Dispersions: how one input of a sweep varies from sample to sample.

Every sample ``i`` of a sweep draws its random inputs from its own part of
one counter-based stream: the uniform variates ``u_ij`` (``j = 0 … n − 1``,
``n`` the variates one sample takes) are the 64-bit words ``i W + j``
(``W = 4⌈n/4⌉``) of NumPy's Philox4x64 generator keyed by
``SeedSequence(seed)``, each word ``k`` mapped to ``u = (⌊k / 2¹¹⌋ + ½) 2⁻⁵³``,
strictly inside (0, 1) (:func:`sample_uniforms`). A counter-based generator
reaches any sample's words directly (Salmon et al., "Parallel random numbers:
as easy as 1, 2, 3", SC'11), so what sample ``i`` gets depends on ``(seed,
i)`` alone, never on the chunk it falls in or on the worker that runs it, and
a chunk of samples draws all its variates in one vectorised call. A
dispersion turns the uniforms of a whole chunk into values at once
(:meth:`Dispersion.values`); standard normal variates are ``Φ⁻¹(u)``
(``scipy.special.ndtri``, inversion: one uniform per normal, no rejection).
The random dispersions of a sweep take their variates in the order of the
``dispersions`` mapping.

A :class:`Grid` is not random: the grids of a sweep form a Cartesian product
whose points the samples visit in C order (the last grid fastest), over and
over when there are more samples than points.

Units are those of the input dispersed (SI: rad/s, kg·m², rad).
"""

from __future__ import annotations

import abc
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike
from scipy import special

from tumble import attitude
from tumble._inertia import as_rotation
from tumble._validate import ValidationError, as_array

__all__ = ["Dispersion", "Normal", "Uniform", "TruncatedNormal", "Grid", "UniformAttitude", "Inertia",
           "Misalignment", "NoiseSeed", "as_dispersion", "sample_uniforms"]


def sample_uniforms(seed: int, lo: int, hi: int, n: int) -> np.ndarray:
    """The uniform variates (hi − lo, n) in (0, 1) of samples ``lo`` to ``hi − 1``: row ``i − lo`` holds the
    words ``i W`` to ``i W + n − 1`` (``W = 4⌈n/4⌉``, a whole number of Philox counter steps per sample) of
    Philox4x64 keyed by ``SeedSequence(seed)``, as ``(⌊k / 2¹¹⌋ + ½) 2⁻⁵³`` (53 random bits, never 0 or 1)."""
    steps = -(-n // 4)  # counter steps per sample, each four 64-bit words
    generator = np.random.Philox(key=np.random.SeedSequence(seed).generate_state(2, np.uint64))
    generator.advance(lo * steps)
    words = generator.random_raw((hi - lo) * 4 * steps).reshape(hi - lo, 4 * steps)[:, :n]
    return ((words >> np.uint64(11)).astype(np.float64) + 0.5) * 2.0**-53


def _array(value, name: str) -> np.ndarray:
    arr = as_array(value, name)
    arr.setflags(write=False)
    return arr


def _set_broadcast(dispersion, **arrays) -> None:
    """Set the fields ``arrays`` of a frozen elementwise dispersion, broadcast to one shape, and its
    ``n_raw``: one uniform variate per component."""
    shape = np.broadcast_shapes(*(a.shape for a in arrays.values()))
    for name, value in arrays.items():
        object.__setattr__(dispersion, name, np.broadcast_to(value, shape))
    object.__setattr__(dispersion, "n_raw", math.prod(shape))


class Dispersion(abc.ABC):
    """How one input varies over the samples; ``shape`` is that of one sample's value."""

    #: Number of uniform variates one sample takes from its stream (0 for a grid).
    n_raw: int = 0

    @property
    @abc.abstractmethod
    def shape(self) -> tuple[int, ...]:
        """Shape of one sample's value."""

    @abc.abstractmethod
    def values(self, u: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Values (m, *shape) of m samples from their uniform variates ``u`` (m, n_raw) in (0, 1);
        ``points`` (m,) are the samples' indices into a grid's values (used by :class:`Grid` only)."""


@dataclass(frozen=True)
class Normal(Dispersion):
    """``x = mean + std z``, ``z`` standard normal per component (``mean``, ``std`` broadcast; std >= 0)."""

    mean: np.ndarray
    std: np.ndarray

    def __post_init__(self):
        mean, std = _array(self.mean, "mean"), _array(self.std, "std")
        if np.any(std < 0):
            raise ValidationError(f"std: must be >= 0, got {std.tolist()}")
        _set_broadcast(self, mean=mean, std=std)

    @property
    def shape(self) -> tuple[int, ...]:
        return self.mean.shape

    def values(self, u: np.ndarray, points: np.ndarray) -> np.ndarray:
        return self.mean + self.std * special.ndtri(u).reshape((-1, *self.shape))

    def __repr__(self):
        return f"Normal(mean={self.mean.tolist()}, std={self.std.tolist()})"


@dataclass(frozen=True)
class Uniform(Dispersion):
    """``x = low + (high − low) u``, ``u`` uniform on (0, 1) per component (``low <= high``)."""

    low: np.ndarray
    high: np.ndarray

    def __post_init__(self):
        low, high = _array(self.low, "low"), _array(self.high, "high")
        if np.any(high < low):
            raise ValidationError(f"high: must be >= low, got low {low.tolist()}, high {high.tolist()}")
        _set_broadcast(self, low=low, high=high)

    @property
    def shape(self) -> tuple[int, ...]:
        return self.low.shape

    def values(self, u: np.ndarray, points: np.ndarray) -> np.ndarray:
        return self.low + (self.high - self.low) * u.reshape((-1, *self.shape))

    def __repr__(self):
        return f"Uniform(low={self.low.tolist()}, high={self.high.tolist()})"


@dataclass(frozen=True)
class TruncatedNormal(Dispersion):
    """A normal ``N(mean, std²)`` restricted to ``[low, high]``, drawn by inverting its distribution function:
    ``x = mean + std Φ⁻¹(Φ(a) + u (Φ(b) − Φ(a)))`` with ``a = (low − mean)/std``, ``b = (high − mean)/std``,
    ``u`` uniform on (0, 1) (no rejection, so one variate per component). ``low`` and ``high`` default to
    ``mean ∓ 3 std``; ``std > 0``."""

    mean: np.ndarray
    std: np.ndarray
    low: np.ndarray | None = None
    high: np.ndarray | None = None

    def __post_init__(self):
        mean, std = _array(self.mean, "mean"), _array(self.std, "std")
        if np.any(std <= 0):
            raise ValidationError(f"std: must be > 0, got {std.tolist()}")
        low = _array(mean - 3 * std if self.low is None else self.low, "low")
        high = _array(mean + 3 * std if self.high is None else self.high, "high")
        if np.any(high <= low):
            raise ValidationError(f"high: must be > low, got low {low.tolist()}, high {high.tolist()}")
        _set_broadcast(self, mean=mean, std=std, low=low, high=high)

    @property
    def shape(self) -> tuple[int, ...]:
        return self.mean.shape

    def values(self, u: np.ndarray, points: np.ndarray) -> np.ndarray:
        a, b = special.ndtr((self.low - self.mean) / self.std), special.ndtr((self.high - self.mean) / self.std)
        x = self.mean + self.std * special.ndtri(a + u.reshape((-1, *self.shape)) * (b - a))
        return np.clip(x, self.low, self.high)  # Φ⁻¹ rounding at the ends stays inside the bounds

    def __repr__(self):
        return (f"TruncatedNormal(mean={self.mean.tolist()}, std={self.std.tolist()}, low={self.low.tolist()}, "
                f"high={self.high.tolist()})")


@dataclass(frozen=True)
class Grid(Dispersion):
    """The values ``points[k]`` (first axis: the grid points) visited in turn: not random. The grids of a
    sweep form a Cartesian product (see the module docstring)."""

    points: np.ndarray

    def __post_init__(self):
        points = _array(self.points, "points")
        if points.ndim == 0 or points.shape[0] == 0:
            raise ValidationError(f"points: a grid needs at least one point along its first axis, got {points.shape}")
        object.__setattr__(self, "points", points)

    @property
    def shape(self) -> tuple[int, ...]:
        return self.points.shape[1:]

    def __len__(self):
        return self.points.shape[0]

    def values(self, u: np.ndarray, points: np.ndarray) -> np.ndarray:
        return self.points[points]

    def __repr__(self):
        return f"Grid({self.points.tolist()})"


@dataclass(frozen=True)
class UniformAttitude(Dispersion):
    """A unit quaternion ``[w, x, y, z]`` uniform on SO(3) (Haar measure): four standard normals, normalised
    (the normalised Gaussian is uniform on the sphere S³, which covers SO(3) twice evenly; K. Shoemake,
    "Uniform random rotations", Graphics Gems III, 1992)."""

    n_raw: int = field(default=4, init=False, repr=False)

    @property
    def shape(self) -> tuple[int, ...]:
        return (4,)

    def values(self, u: np.ndarray, points: np.ndarray) -> np.ndarray:
        z = special.ndtri(u)
        return z / np.linalg.norm(z, axis=-1, keepdims=True)

    def __repr__(self):
        return "UniformAttitude()"


@dataclass(frozen=True)
class Inertia(Dispersion):
    """An inertia tensor (kg·m², body axes) that stays physical: ``J = R_δ R₀ diag(m) R₀ᵀ R_δᵀ``.

    The principal moments ``m_k`` are normal ``N(moments_k, std_k²)`` truncated
    at ``moments_k ± truncation std_k`` (:class:`TruncatedNormal`); ``R₀`` the
    nominal principal axes (columns, body axes; default the body axes);
    ``R_δ`` a small rotation whose rotation vector has independent normal
    components of standard deviation ``angle`` (rad). A rotation keeps ``J``
    symmetric with the moments ``m`` as its eigenvalues, so the rule is on
    the moments alone: every moment of the truncation box must be positive
    and satisfy the triangle inequality ``m_a + m_b >= m_c`` — checked at the
    box's worst corner, ``(moments_a − t std_a) + (moments_b − t std_b) >=
    moments_c + t std_c`` for each ``c`` — or the dispersion is refused here,
    before any sample is drawn.
    """

    moments: np.ndarray
    std: np.ndarray
    angle: float = 0.0
    axes: np.ndarray | None = None
    truncation: float = 3.0

    def __post_init__(self):
        moments = _array(self.moments, "moments")
        std = _array(np.broadcast_to(self.std, (3,)), "std")
        if moments.shape != (3,):
            raise ValidationError(f"moments: must be 3 principal moments (kg m^2), got shape {moments.shape}")
        if np.any(std < 0):
            raise ValidationError(f"std: must be >= 0, got {std.tolist()}")
        angle, truncation = float(self.angle), float(self.truncation)
        if not (math.isfinite(angle) and angle >= 0):
            raise ValidationError(f"angle: must be a finite number >= 0 (rad), got {angle}")
        if not (math.isfinite(truncation) and truncation > 0):
            raise ValidationError(f"truncation: must be a finite number > 0 (standard deviations), got {truncation}")
        low, high = moments - truncation * std, moments + truncation * std
        if np.any(low <= 0):
            raise ValidationError(f"std: moments {moments.tolist()} minus {truncation:g} std {std.tolist()} must stay "
                                  f"> 0 (positive definite), got {low.tolist()}")
        for c in range(3):
            a, b = (k for k in range(3) if k != c)
            if low[a] + low[b] < high[c]:
                raise ValidationError(
                    f"std: the moments could break the triangle inequality I{a + 1} + I{b + 1} >= I{c + 1}: within "
                    f"{truncation:g} std, {low[a]:.6g} + {low[b]:.6g} < {high[c]:.6g} (kg m^2)")
        axes = as_rotation(self.axes, "axes")
        axes.setflags(write=False)
        for name, value in (("moments", moments), ("std", std), ("angle", angle), ("truncation", truncation),
                            ("axes", axes), ("n_raw", 6)):
            object.__setattr__(self, name, value)

    @property
    def shape(self) -> tuple[int, ...]:
        return (3, 3)

    def values(self, u: np.ndarray, points: np.ndarray) -> np.ndarray:
        std = np.where(self.std > 0, self.std, 1.0)  # a fixed moment (std 0): any unit, the box is a point
        box = self.truncation * std
        moments = TruncatedNormal(self.moments, std, self.moments - box, self.moments + box).values(u[:, :3], points)
        moments = np.where(self.std > 0, moments, self.moments)
        rotation = attitude.to_matrix(attitude.from_rotvec(self.angle * special.ndtri(u[:, 3:]))) @ self.axes
        inertia = np.einsum("mij,mj,mkj->mik", rotation, moments, rotation)
        return 0.5 * (inertia + np.swapaxes(inertia, -1, -2))

    def __repr__(self):
        return (f"Inertia(moments={self.moments.tolist()}, std={self.std.tolist()}, angle={self.angle!r}, "
                f"axes={self.axes.tolist()}, truncation={self.truncation!r})")


@dataclass(frozen=True)
class Misalignment(Dispersion):
    """Unit axes (k, 3) (body axes) each tilted from its nominal direction ``axes[j]`` by a small rotation
    whose rotation vector has independent normal components of standard deviation ``angle`` (rad) across
    the axis (the component along it would not move it): the tilt angle is then Rayleigh-distributed with
    scale ``angle``."""

    axes: np.ndarray
    angle: float

    def __post_init__(self):
        axes = as_array(self.axes, "axes", tail=(3,))
        if axes.ndim != 2:
            raise ValidationError(f"axes: must have shape (k, 3), got {axes.shape}")
        norm = np.linalg.norm(axes, axis=-1, keepdims=True)
        if np.any(norm == 0):
            raise ValidationError("axes: must be non-zero vectors")
        angle = float(self.angle)
        if not (math.isfinite(angle) and angle >= 0):
            raise ValidationError(f"angle: must be a finite number >= 0 (rad), got {angle}")
        axes = axes / norm
        axes.setflags(write=False)
        object.__setattr__(self, "axes", axes)
        object.__setattr__(self, "angle", angle)
        object.__setattr__(self, "n_raw", 2 * axes.shape[0])

    @property
    def shape(self) -> tuple[int, ...]:
        return self.axes.shape

    def values(self, u: np.ndarray, points: np.ndarray) -> np.ndarray:
        # two unit vectors across each axis: e1 ⟂ a from the coordinate axis least along a, e2 = a × e1
        a = self.axes
        helper = np.eye(3)[np.abs(a).argmin(axis=-1)]
        e1 = np.cross(a, helper)
        e1 /= np.linalg.norm(e1, axis=-1, keepdims=True)
        e2 = np.cross(a, e1)
        z = special.ndtri(u).reshape(-1, a.shape[0], 2) * self.angle
        rotvec = z[..., :1] * e1 + z[..., 1:] * e2
        return attitude.rotate(attitude.from_rotvec(rotvec), np.broadcast_to(a, rotvec.shape))

    def __repr__(self):
        return f"Misalignment(axes={self.axes.tolist()}, angle={self.angle!r})"


@dataclass(frozen=True)
class NoiseSeed(Dispersion):
    """An integer seed ``⌊2⁵³ u⌋`` in [0, 2⁵³) per sample, ``u`` the sample's uniform variate (for a
    sensor-noise or disturbance model that takes one): like every input fixed by ``(seed, i)``; two of N
    samples share a seed with probability about N²/2⁵⁴. Given as an int64."""

    n_raw: int = field(default=1, init=False, repr=False)

    @property
    def shape(self) -> tuple[int, ...]:
        return ()

    def values(self, u: np.ndarray, points: np.ndarray) -> np.ndarray:
        return np.floor(u[:, 0] * 2.0**53).astype(np.int64)  # ⌊2⁵³ u⌋

    def __repr__(self):
        return "NoiseSeed()"


def as_dispersion(value: Dispersion | ArrayLike, name: str) -> Dispersion:
    """A :class:`Dispersion`, or a fixed value (any array-like) as a one-point :class:`Grid`."""
    if isinstance(value, Dispersion):
        return value
    try:
        return Grid(np.asarray(value, dtype=np.float64)[None])
    except ValidationError as exc:
        raise ValidationError(f"dispersions[{name!r}]: {exc.rule}") from None
    except (TypeError, ValueError):
        raise ValidationError(f"dispersions[{name!r}]: must be a tumble.sweeps dispersion (Normal, Uniform, "
                              f"TruncatedNormal, Grid, UniformAttitude, Inertia, Misalignment, NoiseSeed) or a "
                              f"fixed value, got {type(value).__name__}") from None
