"""Skyfield with the data of ``skyfield-data``: time scales, the Sun and the Moon, and the frame rotations.

Everything is read from the files that ship with the ``skyfield-data``
package (``de421.bsp``: JPL DE421, 1899-07-29 to 2053-10-09;
``finals2000A.all``: IERS UT1−UTC and polar motion, measured to 2025 and
predicted a year on), through skyfield's ``Loader`` pointed at that
package's directory, so nothing reaches the network. Past the end of
``finals2000A.all`` skyfield extrapolates UT1 with its long-term ΔT model
and holds the polar motion at its last value.

Skyfield (and so this module) is imported on first use, never by
``import tumble``.

Frames (IERS Conventions 2010, as skyfield implements them): GCRS axes are
ICRS axes (the inertial frame of tumble's environment); the ITRS is
``R_ITRS_GCRS = W(xₚ, yₚ) R₃(GAST) N P B`` (polar motion, Earth rotation,
IAU 2000A nutation, IAU 2006 precession, frame bias); TEME, the frame of
SGP4, is ``R₃(θ_GMST1982 − GAST) N P B`` (Vallado et al., AIAA 2006-6753,
appendix C).
"""

from __future__ import annotations

import functools
from datetime import datetime, timezone
from importlib.resources import files
from typing import Any

import numpy as np

from tumble._validate import ValidationError

#: seconds per day
DAY = 86400.0


@functools.cache
def loaded() -> tuple[Any, Any]:
    """``(timescale, DE421 kernel)``: UT1 and polar motion from finals2000A.all, the planets from de421.bsp."""
    from skyfield.api import Loader
    from skyfield.data import iers

    load = Loader(str(files("skyfield_data").joinpath("data")), verbose=False)
    ts = load.timescale(builtin=False)
    with load.open("finals2000A.all") as f:
        iers.install_polar_motion_table(ts, iers.parse_x_y_dut1_from_finals_all(f))
    return ts, load("de421.bsp")


def as_utc(epoch: object) -> datetime:
    """``epoch`` as an aware UTC datetime (a naive one is taken as UTC); anything else is refused."""
    if not isinstance(epoch, datetime):
        raise ValidationError(f"epoch: must be a UTC datetime, got {epoch!r}")
    return epoch.replace(tzinfo=timezone.utc) if epoch.tzinfo is None else epoch.astimezone(timezone.utc)


def ephemeris_span() -> tuple[datetime, datetime]:
    """The UTC span covered by DE421 (the Earth, the Moon and the Sun segments)."""
    ts, planets = loaded()
    start = max(s.spk_segment.start_jd for s in planets.segments)
    end = min(s.spk_segment.end_jd for s in planets.segments)
    return ts.tdb_jd(start).utc_datetime(), ts.tdb_jd(end).utc_datetime()


def times(epoch: datetime, t: np.ndarray) -> Any:
    """Skyfield ``Time`` of the instants ``epoch + t`` (``t`` in SI seconds, TT-uniform), refused (naming
    ``epoch``) outside the ephemeris."""
    first, last = ephemeris_span()
    aware = as_utc(epoch)
    end = aware.timestamp() + float(t[-1])
    if aware < first or end > last.timestamp():
        raise ValidationError(f"epoch: the run must lie within the ephemeris DE421 ({first:%Y-%m-%d} to "
                              f"{last:%Y-%m-%d}), got {aware:%Y-%m-%d %H:%M:%S} + {float(t[-1])} s")
    ts, _ = loaded()
    t0 = ts.from_datetime(aware)
    return ts.tt_jd(t0.whole, t0.tt_fraction + t / DAY)


def sun_and_moon_from(r_gcrs: np.ndarray, v_gcrs: np.ndarray, time: Any) -> tuple[np.ndarray, np.ndarray]:
    """Astrometric vectors from the craft (geocentric ``r_gcrs`` (n, 3), m, ``v_gcrs`` (n, 3), m/s) to the Sun
    and to the Moon (light time from the craft), GCRS axes, m: two (n, 3) arrays."""
    from skyfield.constants import AU_M
    from skyfield.positionlib import Barycentric

    _, planets = loaded()
    earth = planets["earth"].at(time)
    craft = Barycentric(earth.position.au + r_gcrs.T / AU_M, earth.velocity.au_per_d + v_gcrs.T / AU_M * DAY,
                        t=time)
    return (np.asarray(craft.observe(planets["sun"]).position.m).T,
            np.asarray(craft.observe(planets["moon"]).position.m).T)


def rotation_itrs_gcrs(time: Any) -> np.ndarray:
    """``R_ITRS_GCRS`` (n, 3, 3): ``r_ITRS = R r_GCRS``."""
    from skyfield.framelib import itrs

    return np.moveaxis(np.asarray(itrs.rotation_at(time)), -1, 0)


def rotation_teme_gcrs(time: Any) -> np.ndarray:
    """``R_TEME_GCRS`` (n, 3, 3): ``r_TEME = R r_GCRS``."""
    from skyfield.sgp4lib import TEME

    return np.moveaxis(np.asarray(TEME.rotation_at(time)), -1, 0)


def geodetic(r_gcrs: np.ndarray, time: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """WGS 84 geodetic latitude and east longitude (degrees) and height above the ellipsoid (m) of GCRS
    positions (n, 3), m."""
    from skyfield.constants import AU_M
    from skyfield.positionlib import Geocentric
    from skyfield.toposlib import wgs84

    position = Geocentric(r_gcrs.T / AU_M, t=time)
    lat, lon = wgs84.latlon_of(position)
    return lat.degrees, lon.degrees, wgs84.height_of(position).m
