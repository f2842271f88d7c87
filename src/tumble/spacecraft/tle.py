"""Two-line element sets (TLE), propagated with SGP4 (the ``sgp4`` package, Vallado et al. 2006).

SGP4 gives the state in TEME (true equator, mean equinox of date), km and
km/s; :meth:`TLE.state_gcrs` turns it to GCRS axes, m and m/s, by the
rotation of skyfield's ``TEME`` frame (``R₃(θ_GMST1982 − GAST) N P B``, see
``tumble.spacecraft._ephemeris``). The velocity is rotated as a vector:
the rate of that rotation (precession and the equation of the equinoxes,
below 10⁻¹¹ rad/s) changes it by less than 10⁻⁴ m/s.

A line is refused unless it is 69 characters long, starts with its line
number, and ends with its checksum: the sum of its first 68 characters'
digits, each minus sign counting 1, modulo 10 (NORAD's rule). The two lines
must name the same satellite. ``sgp4`` (and skyfield) are imported on first
use.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from datetime import datetime, timedelta, timezone
from typing import Any

import numpy as np

from tumble._validate import ValidationError
from tumble.spacecraft import _ephemeris

__all__ = ["TLE", "tle_checksum"]


def tle_checksum(line: str) -> int:
    """NORAD's checksum of a TLE line: the sum of the digits of its first 68 characters, each ``-`` counting
    1, modulo 10."""
    return sum(int(ch) if ch.isdigit() else ch == "-" for ch in line[:68]) % 10


def _checked_line(line: str, number: int) -> str:
    name = f"tle.line{number}"
    if not isinstance(line, str):
        raise ValidationError(f"{name}: must be a string, got {type(line).__name__}")
    line = line.rstrip()
    if len(line) != 69:
        raise ValidationError(f"{name}: must be 69 characters long, got {len(line)}")
    if line[0] != str(number):
        raise ValidationError(f"{name}: must start with its line number {number}, got {line[0]!r}")
    if not line[68].isdigit() or int(line[68]) != tle_checksum(line):
        raise ValidationError(f"{name}: checksum must be {tle_checksum(line)} (the digits of columns 1-68, "
                              f"'-' counting 1, modulo 10), got {line[68]!r}")
    return line


@dataclass(frozen=True)
class TLE:
    """A two-line element set: ``line1``, ``line2`` (69 characters each, checksums checked)."""

    line1: str
    line2: str
    _satrec: Any = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        from sgp4.api import Satrec

        line1, line2 = _checked_line(self.line1, 1), _checked_line(self.line2, 2)
        if line1[2:7] != line2[2:7]:
            raise ValidationError(f"tle.line2: satellite number {line2[2:7]!r} differs from line 1's "
                                  f"{line1[2:7]!r}")
        object.__setattr__(self, "line1", line1)
        object.__setattr__(self, "line2", line2)
        satrec = Satrec.twoline2rv(line1, line2)
        if satrec.error:
            raise ValidationError(f"tle: SGP4 refuses these elements (sgp4 error {satrec.error})")
        object.__setattr__(self, "_satrec", satrec)

    def __reduce__(self):
        """Pickled as its two lines (sgp4's ``Satrec`` is not picklable): for sweeps on other processes."""
        return (TLE, (self.line1, self.line2))

    @property
    def epoch(self) -> datetime:
        """The elements' epoch, a UTC datetime (rounded to the microsecond)."""
        j2000 = datetime(2000, 1, 1, 12, tzinfo=timezone.utc)              # JD 2451545.0 UTC
        return j2000 + timedelta(days=self._satrec.jdsatepoch - 2451545.0) + timedelta(days=self._satrec.jdsatepochF)

    @property
    def period(self) -> float:
        """The Kozai mean motion's period, s."""
        return 2.0 * np.pi / self._satrec.no_kozai * 60.0

    def state_teme(self, epoch: datetime, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """SGP4 position (m) and velocity (m/s) in TEME at the instants ``epoch + t`` (UTC datetime, s):
        (n, 3) each. SGP4 counts time in UTC Julian days, so a leap second inside the run shifts the
        instants after it by 1 s."""
        from sgp4.api import SGP4_ERRORS, jday

        utc = _ephemeris.as_utc(epoch)
        jd, fr = jday(utc.year, utc.month, utc.day, utc.hour, utc.minute, utc.second + 1e-6 * utc.microsecond)
        error, r, v = self._satrec.sgp4_array(np.full(len(t), jd), fr + np.asarray(t, dtype=float) / _ephemeris.DAY)
        if np.any(error):
            k = int(np.flatnonzero(error)[0])
            raise ValidationError(f"tle: SGP4 fails {t[k]} s into the run: {SGP4_ERRORS[int(error[k])]}")
        return 1e3 * r, 1e3 * v

    def state_gcrs(self, epoch: datetime, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Position (m) and velocity (m/s) in GCRS axes at the instants ``epoch + t``: (n, 3) each."""
        r, v = self.state_teme(epoch, t)
        rot = _ephemeris.rotation_teme_gcrs(_ephemeris.times(epoch, t))      # r_TEME = R r_GCRS
        return np.einsum("kji,kj->ki", rot, r), np.einsum("kji,kj->ki", rot, v)
